#pragma once
/// \file cloud_scores.h
/// \brief The per-class cloud scored in 3D against a known world (`sadsplat eval RUN --3d`): the
/// class of every Gaussian against the class of the nearest true surface (plain and opacity
/// weighted), how far the opaque Gaussians sit from a true surface, and how much of the true
/// visible surface has an opaque Gaussian near it, per class.

#include <array>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

namespace sadsplat {
namespace eval {

/// \brief The true surface nearest to a point.
struct TruthSurface {
  float distance = 0;        ///< metres
  std::uint8_t cls = 255;    ///< class id; >= the class count (255) = not scored
};

/// \brief The truth: the nearest true surface of any point.
using NearestTruthSurface = std::function<TruthSurface(const std::array<float, 3>&)>;

/// \brief One Gaussian of the model as the per-class cloud holds it.
struct CloudPoint {
  std::array<float, 3> xyz{0, 0, 0};
  int cls = -1;          ///< its class id, -1 = none
  float opacity = 1.f;   ///< in [0, 1]
};

/// \brief A sample of the true visible surface (seen from above: the topmost surface of a map
/// cell) with its class.
struct SurfaceSample {
  std::array<float, 3> xyz{0, 0, 0};
  std::uint8_t cls = 255;
};

struct CloudScoreOptions {
  int num_classes = 0;
  float opaque = 0.5f;            ///< a Gaussian is opaque at this opacity or above
  float near_metres = 0.5f;       ///< "on a surface": within this distance
  float far_metres = 1.0f;        ///< "off a surface": beyond this distance
  float complete_metres = 0.5f;   ///< a surface sample is covered by an opaque Gaussian this near
};

struct CloudScores {
  std::size_t points = 0;           ///< Gaussians with a class whose nearest surface is scored
  double miou = 0, oacc = 0;        ///< plain: each Gaussian counts once
  double weighted_miou = 0, weighted_oacc = 0;  ///< each Gaussian counts its opacity
  std::vector<double> iou, weighted_iou;        ///< per class; -1 = absent from truth and model
  std::size_t opaque = 0;           ///< opaque Gaussians (any class)
  double median_metres = 0, p90_metres = 0;     ///< distance of opaque centres to the truth
  double share_near = 0, share_far = 0;         ///< of opaque Gaussians: <= near, > far
  double median_all_metres = 0, p90_all_metres = 0;  ///< the same over every Gaussian
  /// Per class of the nearest true surface: the opaque Gaussians there, their median distance,
  /// and the share beyond far_metres (-1 where none).
  std::vector<std::size_t> opaque_per_class;
  std::vector<double> median_per_class, share_far_per_class;
  /// Gaussians counted once, row = the nearest true surface's class, column = the Gaussian's.
  std::vector<std::size_t> confusion;
  std::vector<double> completeness;  ///< per class: share of its surface samples covered; -1 none
  std::vector<std::size_t> samples;  ///< per class: surface samples
  double completeness_all = 0;       ///< over all scored samples
};

/// \brief The points whose centre lies over the rectangle [x0, x1] x [y0, y1] (horizontal
/// coordinates, edges included): the cloud over a map's area, without what lies beyond it.
/// \throws sadsplat::Error when x1 < x0 or y1 < y0
std::vector<CloudPoint> pointsOver(const std::vector<CloudPoint>& points, double x0, double y0,
                                   double x1, double y1);

/// \brief Scores `points` against `truth` and `surface` (see the file comment).
CloudScores scoreCloud(const std::vector<CloudPoint>& points, const NearestTruthSurface& truth,
                       const std::vector<SurfaceSample>& surface, const CloudScoreOptions& options);

}  // namespace eval
}  // namespace sadsplat
