#pragma once
/// \file point_visibility.h
/// \brief Where the scene's sparse points are seen in a view: projected inside the image and not
/// hidden behind a nearer point of the same small pixel cell (a coarse z-buffer: sparse points
/// have no track lists in every format, and the nearest surface is what the view shows).

#include <cstddef>
#include <vector>

#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace pseudo_labels {

/// \brief One sparse point seen at one pixel.
struct PointHit {
  std::size_t pixel;  ///< row-major pixel index in the view
  std::size_t point;  ///< index into scene.points
};

/// \brief The sparse points of `scene` seen in `view`, in the order of scene.points.
/// \param[in] cell z-buffer cell size in pixels: a point is hidden when a point of its cell is
/// more than 2 % nearer
std::vector<PointHit> visiblePoints(const io::Scene& scene, const io::View& view, int cell = 4);

}  // namespace pseudo_labels
}  // namespace sadsplat
