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

bool optionalFileExists(const std::string& path) {
  std::error_code ec;
  const fs::file_status link = fs::symlink_status(path, ec);
  if (ec || !fs::exists(link)) return false;  // nothing there, not even a link
  const fs::file_status target = fs::status(path, ec);
  if (ec || !fs::exists(target)) {
    throw Error(path, "file", "a readable file or none (it is optional)",
                "a symbolic link that cannot be followed (" +
                    (ec ? ec.message() : std::string("its target is missing")) + ")");
  }
  requireRegularFile(path);
  return true;
}

std::vector<std::string> filesIn(const std::string& dir,
                                 const std::function<bool(const std::string&)>& wanted) {
  std::vector<std::string> names;
  std::error_code ec;
  fs::directory_iterator it(dir, ec), end;
  if (ec) throw Error(dir, "folder", "a folder that can be listed", ec.message());
  for (; it != end; it.increment(ec)) {
    if (ec) throw Error(dir, "folder", "a folder that can be listed", ec.message());
    const std::string name = it->path().filename().string();
    if (!wanted(name)) continue;
    std::error_code link_ec;
    const bool regular = fs::is_regular_file(it->path(), link_ec);
    if (link_ec || (!regular && fs::is_symlink(it->symlink_status(link_ec)) &&
                    !fs::exists(it->path(), link_ec))) {
      throw Error(it->path().string(), "file", "a readable file",
                  "a symbolic link that cannot be followed (" +
                      (link_ec ? link_ec.message() : std::string("its target is missing")) + ")");
    }
    if (regular) names.push_back(name);
  }
  std::sort(names.begin(), names.end());
  return names;
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
