#include "sadsplat/pseudo_labels/point_visibility.h"

#include <algorithm>
#include <cmath>
#include <limits>

namespace sadsplat {
namespace pseudo_labels {

std::vector<PointHit> visiblePoints(const io::Scene& scene, const io::View& view, int cell) {
  const int W = view.camera.width, H = view.camera.height;
  cell = std::max(1, cell);
  const std::array<double, 9> R = view.camera.rotation();
  const auto& t = view.camera.tvec;
  const int CW = (W + cell - 1) / cell, CH = (H + cell - 1) / cell;
  std::vector<float> zbuf(static_cast<std::size_t>(CW) * CH, std::numeric_limits<float>::max());
  struct Projected {
    std::size_t pixel, cell;
    float z;
    std::size_t point;
  };
  std::vector<Projected> projected;
  for (std::size_t p = 0; p < scene.points.size(); ++p) {
    const auto& X = scene.points[p].xyz;
    const double xc = R[0] * X[0] + R[1] * X[1] + R[2] * X[2] + t[0];
    const double yc = R[3] * X[0] + R[4] * X[1] + R[5] * X[2] + t[1];
    const double zc = R[6] * X[0] + R[7] * X[1] + R[8] * X[2] + t[2];
    if (zc <= 1e-6) continue;
    const double u = view.camera.fx * xc / zc + view.camera.cx,
                 v = view.camera.fy * yc / zc + view.camera.cy;
    if (!(u >= 0 && v >= 0 && u < W && v < H)) continue;
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
