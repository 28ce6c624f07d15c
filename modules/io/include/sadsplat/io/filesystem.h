#pragma once
/// \file filesystem.h
/// \brief The few file-system questions sadsplat asks, answered in one place (std::filesystem),
/// with failures turned into sadsplat::Error.

#include <functional>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief Whether anything exists at `path`.
bool pathExists(const std::string& path);
/// \brief Whether `path` is a directory.
bool isDirectory(const std::string& path);
/// \brief Whether `path` is a regular file (not a directory, FIFO, device or socket).
bool isRegularFile(const std::string& path);
/// \brief Creates `dir` and every missing parent; an existing directory is fine.
/// \throws sadsplat::Error naming the directory if it cannot be created (or is a file)
void makeDirectory(const std::string& dir);
/// \brief Creates the missing parent directories of the file `path` (nothing if it has none).
/// \throws sadsplat::Error naming the directory if it cannot be created
void makeParentDirectory(const std::string& path);
/// \brief Throws unless `path` is an existing regular file: readers call this first, so that a
/// FIFO, a device or a directory is an error instead of a blocking or endless read.
/// \throws sadsplat::Error naming the file and what it is
void requireRegularFile(const std::string& path);
/// \brief Whether an optional file is there: false when nothing is at `path`, true for a
/// readable regular file (or a link to one).
/// \throws sadsplat::Error naming the file when something is there that cannot be read as a file:
/// a symbolic link whose target is missing or loops, a directory, a FIFO or device
bool optionalFileExists(const std::string& path);
/// \brief The names of the regular files in `dir` (links followed) for which `wanted(name)` is
/// true, sorted.
/// \throws sadsplat::Error naming the entry when a wanted name is a link that cannot be followed
/// (a loop, a missing target), or naming `dir` when it cannot be listed
std::vector<std::string> filesIn(const std::string& dir,
                                 const std::function<bool(const std::string&)>& wanted);
/// \brief Whether `text` ends with `suffix`.
bool endsWith(const std::string& text, const std::string& suffix);
/// \brief The file name extension of `path` in lower case, with its dot (".ply"), or "".
std::string lowerExtension(const std::string& path);

}  // namespace io
}  // namespace sadsplat
