#include "sadsplat/eval/cloud_scores.h"

#include <algorithm>
#include <cmath>
#include <unordered_map>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"

namespace sadsplat {
namespace eval {
namespace {

// IoU per class from a (weighted) confusion matrix, -1 where a class is absent from both.
std::vector<double> iouOf(const std::vector<double>& m, int n, double* miou, double* oacc) {
  std::vector<double> iou(n, -1.0);
  double correct = 0, total = 0, sum = 0;
  int present = 0;
  for (int c = 0; c < n; ++c) {
    double row = 0, col = 0;
    for (int k = 0; k < n; ++k) {
      row += m[c * n + k];
      col += m[k * n + c];
    }
    const double tp = m[c * n + c];
    correct += tp;
    total += row;
    const double denominator = row + col - tp;
    if (denominator > 0) {
      iou[c] = tp / denominator;
      sum += iou[c];
      ++present;
    }
  }
  *miou = present ? sum / present : 0.0;
  *oacc = total > 0 ? correct / total : 0.0;
  return iou;
}

double quantile(std::vector<float> v, double q) { return quantileInPlace(v, q); }

}  // namespace

std::vector<CloudPoint> pointsOver(const std::vector<CloudPoint>& points, double x0, double y0,
                                   double x1, double y1) {
  if (!(x1 >= x0) || !(y1 >= y0)) {
    throw Error("<cloud scores>", "area", "x0 <= x1 and y0 <= y1",
                std::to_string(x0) + ".." + std::to_string(x1) + " x " + std::to_string(y0) +
                    ".." + std::to_string(y1));
  }
  std::vector<CloudPoint> over;
  for (const CloudPoint& p : points) {
    if (p.xyz[0] >= x0 && p.xyz[0] <= x1 && p.xyz[1] >= y0 && p.xyz[1] <= y1) over.push_back(p);
  }
  return over;
}

CloudScores scoreCloud(const std::vector<CloudPoint>& points, const NearestTruthSurface& truth,
                       const std::vector<SurfaceSample>& surface, const CloudScoreOptions& o) {
  const int n = o.num_classes;
  if (n <= 0 || n > 255) {
    throw Error("<3d scores>", "num_classes", "1..255 classes", std::to_string(n));
  }
  CloudScores s;
  std::vector<double> plain(static_cast<std::size_t>(n) * n, 0.0), weighted(plain);
  std::vector<float> distances, all_distances;
  std::vector<std::vector<float>> class_distances(n);
  s.confusion.assign(static_cast<std::size_t>(n) * n, 0);
  std::size_t near = 0, far = 0;
  // Opaque centres in a voxel hash of the completeness distance, for the coverage of the truth.
  const float voxel = o.complete_metres;
  const auto key = [voxel](float x, float y, float z) {
    const auto q = [voxel](float v) { return static_cast<std::int64_t>(std::floor(v / voxel)); };
    return (q(x) * 73856093) ^ (q(y) * 19349663) ^ (q(z) * 83492791);
  };
  std::unordered_multimap<std::int64_t, std::array<float, 3>> opaque_at;
  for (const CloudPoint& p : points) {
    const TruthSurface t = truth(p.xyz);
    all_distances.push_back(t.distance);
    if (p.cls >= 0 && p.cls < n && t.cls < n) {
      ++s.points;
      plain[static_cast<std::size_t>(t.cls) * n + p.cls] += 1.0;
      ++s.confusion[static_cast<std::size_t>(t.cls) * n + p.cls];
      weighted[static_cast<std::size_t>(t.cls) * n + p.cls] += p.opacity;
    }
    if (p.opacity >= o.opaque) {
      ++s.opaque;
      distances.push_back(t.distance);
      near += t.distance <= o.near_metres;
      far += t.distance > o.far_metres;
      if (t.cls < n) class_distances[t.cls].push_back(t.distance);
      opaque_at.emplace(key(p.xyz[0], p.xyz[1], p.xyz[2]), p.xyz);
    }
  }
  s.iou = iouOf(plain, n, &s.miou, &s.oacc);
  s.weighted_iou = iouOf(weighted, n, &s.weighted_miou, &s.weighted_oacc);
  s.median_metres = quantile(distances, 0.5);
  s.p90_metres = quantile(distances, 0.9);
  s.opaque_per_class.assign(n, 0);
  s.median_per_class.assign(n, -1.0);
  s.share_far_per_class.assign(n, -1.0);
  for (int c = 0; c < n; ++c) {
    const auto& d = class_distances[c];
    s.opaque_per_class[c] = d.size();
    if (d.empty()) continue;
    s.median_per_class[c] = quantile(d, 0.5);
    s.share_far_per_class[c] =
        double(std::count_if(d.begin(), d.end(), [&](float v) { return v > o.far_metres; })) /
        d.size();
  }
  s.median_all_metres = quantile(all_distances, 0.5);
  s.p90_all_metres = quantile(all_distances, 0.9);
  s.share_near = s.opaque ? double(near) / s.opaque : 0.0;
  s.share_far = s.opaque ? double(far) / s.opaque : 0.0;

  s.completeness.assign(n, -1.0);
  s.samples.assign(n, 0);
  std::vector<std::size_t> covered(n, 0);
  std::size_t all = 0, all_covered = 0;
  const float r2 = o.complete_metres * o.complete_metres;
  for (const SurfaceSample& q : surface) {
    if (q.cls >= n) continue;
    ++s.samples[q.cls];
    ++all;
    bool hit = false;
    for (int dz = -1; dz <= 1 && !hit; ++dz) {
      for (int dy = -1; dy <= 1 && !hit; ++dy) {
        for (int dx = -1; dx <= 1 && !hit; ++dx) {
          const auto range = opaque_at.equal_range(
              key(q.xyz[0] + dx * voxel, q.xyz[1] + dy * voxel, q.xyz[2] + dz * voxel));
          for (auto it = range.first; it != range.second && !hit; ++it) {
            const auto& c = it->second;
            const float d2 = (c[0] - q.xyz[0]) * (c[0] - q.xyz[0]) +
                             (c[1] - q.xyz[1]) * (c[1] - q.xyz[1]) +
                             (c[2] - q.xyz[2]) * (c[2] - q.xyz[2]);
            hit = d2 <= r2;
          }
        }
      }
    }
    covered[q.cls] += hit;
    all_covered += hit;
  }
  for (int c = 0; c < n; ++c) {
    if (s.samples[c] > 0) s.completeness[c] = double(covered[c]) / s.samples[c];
  }
  s.completeness_all = all ? double(all_covered) / all : 0.0;
  return s;
}

}  // namespace eval
}  // namespace sadsplat
