#pragma once
/// \file file_info.h
/// \brief Human-readable summaries of the files sadsplat reads (`sadsplat info`).

#include <string>

namespace sadsplat {
namespace io {

/// \brief A multi-line summary of a 3DGS PLY, a PCD, a scene directory or a scene cache:
/// counts, SH degree, bounding box, classes, views.
/// \throws sadsplat::Error if the file is of none of these kinds or is invalid
std::string describeFile(const std::string& path);

}  // namespace io
}  // namespace sadsplat
