#pragma once
/// \file exif_orientation.h
/// \brief A photo's EXIF Orientation tag (0x0112). COLMAP and nerfstudio read pixels as stored and
/// ignore it, so sadsplat does too when it imports a scene; `sadsplat sfm` makes upright copies
/// of rotated photos before COLMAP sees them (pipeline/sfm_run.h).

#include <string>

namespace sadsplat {
namespace io {

/// \brief The Orientation tag of the photo at `path`: 1 (stored upright) to 8, as TIFF 6.0
/// defines it; 1 when the photo has no EXIF, no such tag, a value outside 1-8, or this build
/// reads no EXIF (haveExif() in georeference.h).
/// \throws sadsplat::Error when `path` is not a readable regular file
int readExifOrientation(const std::string& path);

}  // namespace io
}  // namespace sadsplat
