#pragma once
/// \file region_features.h
/// \brief Descriptors of image regions for the built-in few-shot scorer: colour (CIELab mean and
/// spread, chroma, greenness), texture (gradient energy, structure-tensor coherence, Laplacian
/// energy), context (Lab mean of a window three times the region size) and, when the scene has
/// sparse points, the height above ground of the points seen in the region. None of them depends
/// on the image size or on the flying height (no areas or pixel distances).

#include <vector>

#include "sadsplat/io/scene.h"
#include "sadsplat/pseudo_labels/superpixels.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief Number of values per region returned by regionFeatures.
constexpr int kRegionFeatureDim = 17;

/// \brief Heights above ground of the scene's sparse points, for the geometric features.
struct SceneGeometry {
  std::array<double, 3> up{0, 0, 1};  ///< unit vector away from the ground (towards the cameras)
  std::vector<float> height;          ///< per sparse point, above the 2nd height percentile
  float median_height = 0;
  float scale = 1;  ///< spread of the heights (for normalisation)

  /// \brief Up = the mean of the cameras' backward viewing directions (aerial views look down).
  static SceneGeometry fromScene(const io::Scene& scene);
};

/// \brief Descriptors [num_regions x kRegionFeatureDim] of the regions of `view`.
/// \param[in] geometry the scene's sparse-point heights, or nullptr (height features set to 0)
std::vector<float> regionFeatures(const io::Scene& scene, const io::View& view,
                                  const Segmentation& segmentation, const SceneGeometry* geometry);

}  // namespace pseudo_labels
}  // namespace sadsplat
