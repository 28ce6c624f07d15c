#include "sadsplat/io/atomic_file.h"

#include <unistd.h>

#include <sys/stat.h>
#include <algorithm>
#include <cerrno>
#include <cstdint>
#include <cstdio>
#include <cstring>
#include <fstream>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {
namespace {

// "<path>.tmp-<pid>" beside the output; when that name would pass NAME_MAX (255 bytes on the
// usual file systems) a short hidden name in the same directory, so that every output name the
// file system accepts can also be written atomically.
std::string temporaryPathFor(const std::string& path) {
  const std::string suffix = ".tmp-" + std::to_string(::getpid());
  const std::size_t slash = path.find_last_of('/');
  const std::string dir = slash == std::string::npos ? "" : path.substr(0, slash + 1);
  const std::string name = slash == std::string::npos ? path : path.substr(slash + 1);
  constexpr std::size_t kNameMax = 255;
  if (name.size() + suffix.size() <= kNameMax) return path + suffix;
  std::uint64_t hash = 14695981039346656037ull;  // FNV-1a of the name: distinct per output
  for (const char c : name) {
    hash ^= static_cast<unsigned char>(c);
    hash *= 1099511628211ull;
  }
  return dir + ".sadsplat-" + std::to_string(hash) + suffix;
}

}  // namespace

void writeTextFileAtomically(const std::string& path, const std::string& text) {
  writeFileAtomically(path, [&](std::ostream& out) { out << text; });
}

void writeViaTemporaryPath(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write) {
  // An output path names what the user wants; its missing parent directories are made here, so
  // every writer accepts a nested path that does not exist yet (`--out out/a/b/model.ply`).
  makeParentDirectory(path);
  const std::string tmp = temporaryPathFor(path);
  try {
    try {
      write(tmp);
    } catch (const Error&) {
      throw;
    } catch (const std::exception& e) {
      // Third-party writers (PCL, OpenCV) throw their own types: keep the one-line error form.
      throw Error(path, "write", "success", e.what());
    }
    struct stat st {};
    if (::stat(tmp.c_str(), &st) != 0) {
      throw Error(path, "write", "the file to be written", "the writer produced nothing");
    }
    if (std::rename(tmp.c_str(), path.c_str()) != 0) {
      throw Error(path, "rename from " + tmp, "success", std::strerror(errno));
    }
  } catch (...) {
    std::remove(tmp.c_str());
    throw;
  }
}

void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write) {
  writeViaTemporaryPath(path, [&](const std::string& tmp) {
    std::ofstream out(tmp, std::ios::binary | std::ios::trunc);
    if (!out) {
      throw Error(path, "open for writing", "a writable location", std::strerror(errno));
    }
    write(out);
    out.flush();
    if (!out) throw Error(path, "write", "all bytes written", "a stream error (disk full?)");
  });
}

std::string readFileStart(const std::string& path, std::size_t max_bytes) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "file", "an existing, readable file", "cannot open it");
  in.seekg(0, std::ios::end);
  const auto size = static_cast<std::size_t>(std::max<std::streamoff>(0, in.tellg()));
  in.seekg(0, std::ios::beg);
  std::string bytes(std::min(size, max_bytes), '\0');
  in.read(bytes.data(), static_cast<std::streamsize>(max_bytes));
  if (in.bad()) throw Error(path, "file", "a readable file", "a read error");
  bytes.resize(static_cast<std::size_t>(in.gcount()));
  return bytes;
}

std::string readWholeFile(const std::string& path) {
  requireRegularFile(path);
  std::ifstream in(path, std::ios::binary);
  if (!in) throw Error(path, "file", "an existing, readable file", "cannot open it");
  std::ostringstream buffer;
  buffer << in.rdbuf();
  if (in.bad()) throw Error(path, "file", "a readable file", "a read error");
  return buffer.str();
}

}  // namespace io
}  // namespace sadsplat
