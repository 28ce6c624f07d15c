#include "sadsplat/io/output_set.h"

#include <unistd.h>

#include <algorithm>
#include <filesystem>
#include <system_error>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace io {

namespace fs = std::filesystem;

OutputSet::OutputSet(std::string dir, std::vector<std::string> members)
    : dir_(std::move(dir)), members_(std::move(members)) {
  makeDirectory(dir_);
  staging_ = dir_ + "/.sadsplat-staging-" + std::to_string(::getpid());
  std::error_code ec;
  fs::remove_all(staging_, ec);  // a previous run of this pid that was killed
  fs::create_directory(staging_, ec);
  if (ec) throw Error(dir_, "output directory", "a writable directory", ec.message());
}

OutputSet::~OutputSet() {
  std::error_code ec;
  fs::remove_all(staging_, ec);  // never throws: nothing to do about a failure here
}

std::string OutputSet::path(const std::string& name) const {
  if (std::find(members_.begin(), members_.end(), name) == members_.end()) {
    throw Error(dir_, name, "a member of the output set", "an unknown name (a bug)");
  }
  return staging_ + "/" + name;
}

void OutputSet::commit() {
  for (const std::string& name : members_) {
    const fs::path staged = staging_ + "/" + name, target = dir_ + "/" + name;
    std::error_code ec;
    const bool written = fs::exists(staged, ec);
    // A member of the old set that this run did not write goes; a folder member is replaced
    // whole (fs::rename cannot replace a non-empty folder).
    if (!written || fs::is_directory(target, ec)) fs::remove_all(target, ec);
    if (!written) continue;
    fs::rename(staged, target, ec);
    if (ec) throw Error(target.string(), "output", "a file that can be moved into place", ec.message());
  }
}

}  // namespace io
}  // namespace sadsplat
