#include "sadsplat/pseudo_labels/point_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sadsplat {
namespace pseudo_labels {

std::vector<PointHit> visiblePoints(const io::Scene& scene, const io::View& view, int cell) {
  const int W = view.camera.width, H = view.camera.height;
  cell = std::max(1, cell);
  const io::PointProjector camera(view.camera);
  const int CW = (W + cell - 1) / cell, CH = (H + cell - 1) / cell;
  std::vector<float> zbuf(static_cast<std::size_t>(CW) * CH, std::numeric_limits<float>::max());
  struct Projected {
    std::size_t pixel, cell;
    float z;
    std::size_t point;
  };
  std::vector<Projected> projected;
  for (std::size_t p = 0; p < scene.points.size(); ++p) {
    double u = 0, v = 0, zc = 0;
    if (!camera.project(scene.points[p].xyz, &u, &v, &zc)) continue;
    const int px = static_cast<int>(u), py = static_cast<int>(v);
    const std::size_t c = static_cast<std::size_t>(py / cell) * CW + px / cell;
    zbuf[c] = std::min(zbuf[c], static_cast<float>(zc));
    projected.push_back({static_cast<std::size_t>(py) * W + px, c, static_cast<float>(zc), p});
  }
  std::vector<PointHit> hits;
  hits.reserve(projected.size());
  for (const Projected& h : projected) {
    if (h.z <= zbuf[h.cell] * 1.02f) hits.push_back({h.pixel, h.point});
  }
  return hits;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
