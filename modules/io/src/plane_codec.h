#pragma once
// Lossless planes of the scene cache (version 3): images and pseudo-label region maps are stored
// as prediction residuals, deflated. Images: each channel a plane of its own (RGB as G, R - G,
// B - G mod 256: the reversible colour transform that decorrelates the channels), every byte
// replaced by its difference (mod 256) to the median edge detector of LOCO-I / JPEG-LS (the left
// and upper neighbours' min or max at an edge, else left + up - upper-left), Huffman-coded by
// deflate without string matching. On the 800x450 Brighton photos the RGB planes shrink to 0.54
// of their size (0.78 without the colour transform). Region maps (int32 per pixel, piecewise
// constant): the difference to the left neighbour (mod 2^32), deflated. Decoding is bounded by
// the sizes the caller expects, not by what the compressed bytes claim.

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace io {
namespace planes {

/// The residual planes of `image`, deflated.
std::vector<std::uint8_t> encodeImage(const std::string& path, const Image8& image);

/// Inverse of encodeImage for an image of the given size.
/// \throws sadsplat::Error naming `path` and `field` when the stream is corrupt or of another size
Image8 decodeImage(const std::string& path, const std::string& field, const std::uint8_t* data,
                   std::size_t size, int width, int height, int channels);

/// A region map of `width`-pixel rows as left differences, deflated.
std::vector<std::uint8_t> encodeRegions(const std::string& path,
                                        const std::vector<std::int32_t>& regions, int width);

/// Inverse of encodeRegions for `count` pixels in rows of `width`.
std::vector<std::int32_t> decodeRegions(const std::string& path, const std::string& field,
                                        const std::uint8_t* data, std::size_t size,
                                        std::size_t count, int width);

}  // namespace planes
}  // namespace io
}  // namespace sadsplat
