#pragma once
/// \file superpixels.h
/// \brief SLIC superpixels (Achanta et al. 2012), the built-in backend's mask generator: k-means
/// in (CIELab, x, y) seeded on a regular grid, each centre searching a 2S x 2S window, followed
/// by a connectivity pass that merges fragments into a neighbour. Plain C++ (no OpenCV), so the
/// GPU build can run it too.

#include <cstdint>
#include <vector>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief SLIC parameters.
struct SlicOptions {
  int region_size = 16;       ///< grid step S in pixels
  double compactness = 10.0;  ///< m: weight of the spatial distance against the Lab distance
  int iterations = 10;
};

/// \brief A partition of an image into regions (targets).
struct Segmentation {
  int width = 0;
  int height = 0;
  int num_regions = 0;
  std::vector<std::int32_t> region;  ///< per pixel, row-major: 0..num_regions-1, or -1 (masked)
};

/// \brief Segments an RGB image; pixels whose mask is 0 belong to no region.
/// \param[in] rgb 3-channel image
/// \param[in] mask 1-channel validity mask of the same size (may be empty: all valid)
/// \throws sadsplat::Error on mismatched sizes or a region size below 2
Segmentation slicSuperpixels(const io::Image8& rgb, const io::Image8& mask,
                             const SlicOptions& options = {});

/// \brief Converts an sRGB byte triple to CIELab (D65), L in [0, 100].
void srgbToLab(std::uint8_t r, std::uint8_t g, std::uint8_t b, float lab[3]);

/// \brief CIELab of every pixel of a 3-channel sRGB image, interleaved (L, a, b per pixel).
std::vector<float> imageToLab(const io::Image8& rgb);

}  // namespace pseudo_labels
}  // namespace sadsplat
