#pragma once
/// \file image_file.h
/// \brief Image files as sadsplat reads them: the size an image file claims, read from its header before anything is decoded, and
/// the pixel budget every image reader of sadsplat checks it against: a 676-byte JPEG that
/// claims 30000x30000 pixels is refused in microseconds instead of taking 2.8 GB to decode.

#include <cstdint>
#include <string>

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/core/mat.hpp>
#endif

namespace sadsplat {
namespace io {

/// \brief The most pixels sadsplat decodes from one image file: 2^28 (268 MP; a 100 MP aerial
/// camera's photo is 1e8).
constexpr std::uint64_t kMaxImagePixels = 1ull << 28;
/// \brief The most pixels one byte of a compressed image can stand for when checking a header's
/// claim against the file's size (JPEG codes each 8x8 block's DC term in at least one bit per
/// component: <= 512 pixels per byte; deflate expands at most 1032:1).
constexpr std::uint64_t kMaxPixelsPerFileByte = 4096;

/// \brief What an image file's header says.
struct ImageHeader {
  std::string format;       ///< "png", "jpeg", "webp", or "" when not recognised
  std::uint32_t width = 0;  ///< as stored (before an EXIF rotation)
  std::uint32_t height = 0;
  int png_colour_type = -1;  ///< PNG's IHDR colour type (0 grey, 2 RGB, 3 palette, 4 grey + alpha,
                             ///< 6 RGBA); -1 for other formats
};

/// \brief Reads the header of a PNG, JPEG or WebP file (format "" for others).
/// \throws sadsplat::Error naming the file when it cannot be read or a recognised header is cut off
ImageHeader readImageHeader(const std::string& path);

/// \brief Throws unless the image at `path` may be decoded: a recognised header's width x height
/// within kMaxImagePixels and within kMaxPixelsPerFileByte x the file's size.
/// \param[in] what what the image is, for the message ("photo", "label map")
/// \returns the header
ImageHeader checkImageBudget(const std::string& path, const std::string& what);

#if SADSPLAT_HAVE_OPENCV
/// \brief cv::imread after checkImageBudget; OpenCV's exceptions and an empty result become one
/// sadsplat::Error naming the file. `header` (if given) receives what the header said.
cv::Mat decodeImage(const std::string& path, int imread_flags, const std::string& what,
                    ImageHeader* header = nullptr);
#endif

}  // namespace io
}  // namespace sadsplat
