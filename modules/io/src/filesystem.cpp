#include "sadsplat/io/filesystem.h"

#include <algorithm>
#include <cctype>
#include <filesystem>
#include <system_error>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace io {

namespace fs = std::filesystem;

bool pathExists(const std::string& path) {
  std::error_code ec;
  return fs::exists(path, ec);
}

bool isDirectory(const std::string& path) {
  std::error_code ec;
  return fs::is_directory(path, ec);
}

bool isRegularFile(const std::string& path) {
  std::error_code ec;
  return fs::is_regular_file(path, ec);
}

void makeDirectory(const std::string& dir) {
  std::error_code ec;
  if (fs::is_directory(dir, ec)) return;
  fs::create_directories(dir, ec);
  if (ec || !fs::is_directory(dir)) {
    throw Error(dir, "directory", "a directory that can be created",
                ec ? ec.message() : std::string("a file of that name exists"));
  }
}

void makeParentDirectory(const std::string& path) {
  const fs::path parent = fs::path(path).parent_path();
  if (!parent.empty()) makeDirectory(parent.string());
}

void requireRegularFile(const std::string& path) {
  std::error_code ec;
  const fs::file_status st = fs::status(path, ec);
  if (ec || !fs::exists(st)) throw Error(path, "file", "an existing, readable file", "missing");
  if (fs::is_directory(st)) throw Error(path, "file", "a regular file", "a directory");
  if (!fs::is_regular_file(st)) {
    throw Error(path, "file", "a regular file", "a FIFO, socket or device");
  }
}

bool endsWith(const std::string& text, const std::string& suffix) {
  return text.size() >= suffix.size() &&
         text.compare(text.size() - suffix.size(), suffix.size(), suffix) == 0;
}

std::string lowerExtension(const std::string& path) {
  std::string ext = fs::path(path).extension().string();
  std::transform(ext.begin(), ext.end(), ext.begin(),
                 [](unsigned char c) { return static_cast<char>(std::tolower(c)); });
  return ext;
}

}  // namespace io
}  // namespace sadsplat
