#pragma once
/// \file filesystem.h
/// \brief The few file-system questions sadsplat asks, answered in one place.

#include <string>

namespace sadsplat {
namespace io {

/// \brief Whether anything exists at `path`.
bool pathExists(const std::string& path);
/// \brief Whether `path` is a directory.
bool isDirectory(const std::string& path);
/// \brief Whether `path` is a regular file.
bool isRegularFile(const std::string& path);
/// \brief Creates `dir` (its parent must exist); an existing directory is fine.
/// \throws sadsplat::Error naming the directory if it cannot be created
void makeDirectory(const std::string& dir);
/// \brief Whether `text` ends with `suffix`.
bool endsWith(const std::string& text, const std::string& suffix);

}  // namespace io
}  // namespace sadsplat
