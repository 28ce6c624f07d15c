#pragma once
/// \file atomic_file.h
/// \brief Writing a file so that readers see either the old or the complete new content.

#include <cstddef>
#include <functional>
#include <ostream>
#include <string>

namespace sadsplat {
namespace io {

/// \brief Writes `path` atomically: `write` fills a temporary file in the same directory, which
/// is flushed and then renamed over `path`. On any failure the temporary file is removed, `path`
/// is left as it was, and sadsplat::Error is thrown.
/// \param[in] path destination file; missing parent directories are created
/// \param[in] write callback that writes the whole content to the stream (binary mode)
void writeFileAtomically(const std::string& path, const std::function<void(std::ostream&)>& write);

/// \brief writeFileAtomically of a text (or any bytes) held in memory.
void writeTextFileAtomically(const std::string& path, const std::string& text);

/// \brief Same guarantee for writers that take a file name (PCL's, OpenCV's): `write` writes
/// the temporary path it is given, which is then renamed over `path`. `write` reports failure
/// by throwing or by leaving no file at the temporary path.
void writeViaTemporaryPath(const std::string& path,
                           const std::function<void(const std::string& tmp_path)>& write);

/// \brief Reads the first `max_bytes` of a file (all of it if it is shorter): enough for a
/// format's header, without reading the data that follows it.
/// \throws sadsplat::Error naming the file if it is missing, unreadable or not a regular file
std::string readFileStart(const std::string& path, std::size_t max_bytes);

/// \brief Reads a whole file into memory.
/// \throws sadsplat::Error naming the file if it is missing, unreadable or not a regular file
/// (a FIFO or device would block or never end)
std::string readWholeFile(const std::string& path);

}  // namespace io
}  // namespace sadsplat
