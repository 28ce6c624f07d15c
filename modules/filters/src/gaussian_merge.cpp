// Moment-matched merges of Gaussians in voxels (see gaussian_merge.h).
#include "sadsplat/filters/gaussian_merge.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <memory>
#include <set>
#include <tuple>
#include <unordered_map>

#include <pcl/kdtree/kdtree_flann.h>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace filters {
namespace {

constexpr double kMaxMergedAlpha = 0.999;
constexpr double kMinMergedAlpha = 1e-6;
constexpr double kMinVariance = 1e-20;

struct CellKey {
  std::int64_t x, y, z;
  std::uint32_t label;
  bool operator==(const CellKey& o) const {
    return x == o.x && y == o.y && z == o.z && label == o.label;
  }
};

struct CellKeyHash {
  std::size_t operator()(const CellKey& k) const {
    std::size_t h = std::hash<std::int64_t>()(k.x);
    h = h * 1000003u ^ std::hash<std::int64_t>()(k.y);
    h = h * 1000003u ^ std::hash<std::int64_t>()(k.z);
    return h * 1000003u ^ std::hash<std::uint32_t>()(k.label);
  }
};

void checkVoxel(double voxel) {
  if (!(voxel > 0) || !std::isfinite(voxel)) {
    throw Error("<merge>", "voxel size", "a positive finite length", std::to_string(voxel));
  }
}

// Every Gaussian's group (cells of `voxel` from the cloud's lowest corner, and label when
// class-aware), groups numbered in the order of their first Gaussian.
std::vector<std::size_t> groupInVoxels(const pcl::PointCloud<GaussianPoint>& cloud,
                                       const GaussianMergeOptions& o, std::size_t* groups) {
  checkVoxel(o.voxel_size);
  double lo[3] = {std::numeric_limits<double>::max(), std::numeric_limits<double>::max(),
                  std::numeric_limits<double>::max()};
  for (const GaussianPoint& p : cloud) {
    lo[0] = std::min(lo[0], double(p.x));
    lo[1] = std::min(lo[1], double(p.y));
    lo[2] = std::min(lo[2], double(p.z));
  }
  std::unordered_map<CellKey, std::size_t, CellKeyHash> index;
  index.reserve(cloud.size());
  std::vector<std::size_t> group(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const GaussianPoint& p = cloud[i];
    const CellKey key{static_cast<std::int64_t>(std::floor((p.x - lo[0]) / o.voxel_size)),
                      static_cast<std::int64_t>(std::floor((p.y - lo[1]) / o.voxel_size)),
                      static_cast<std::int64_t>(std::floor((p.z - lo[2]) / o.voxel_size)),
                      o.class_aware ? p.label : 0u};
    group[i] = index.emplace(key, index.size()).first->second;
  }
  *groups = index.size();
  return group;
}

double sigmoidOf(double x) { return 1.0 / (1.0 + std::exp(-x)); }

// A Gaussian's weight in a merge: opacity x the area of its ellipsoid's footprint, up to a constant
// (s0 s1 + s0 s2 + s1 s2: what it covers on screen, whichever way it is seen).
double massOf(const GaussianPoint& p) {
  const double s0 = std::exp(double(p.scale[0])), s1 = std::exp(double(p.scale[1])),
               s2 = std::exp(double(p.scale[2]));
  return sigmoidOf(p.opacity) * (s0 * s1 + s0 * s2 + s1 * s2);
}

}  // namespace

GaussianPoint mergeGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                             const std::vector<std::size_t>& indices) {
  if (indices.empty()) throw Error("<merge>", "indices", "at least one Gaussian", "none");
  if (indices.size() == 1) return cloud[indices[0]];
  std::vector<double> mass(indices.size());
  double total = 0;
  for (std::size_t j = 0; j < indices.size(); ++j) {
    mass[j] = massOf(cloud[indices[j]]);
    total += mass[j];
  }
  if (!(total > 0) || !std::isfinite(total)) {  // all transparent: an unweighted mean
    std::fill(mass.begin(), mass.end(), 1.0);
    total = static_cast<double>(indices.size());
  }
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (std::size_t j = 0; j < indices.size(); ++j) {
    const GaussianPoint& p = cloud[indices[j]];
    mean += mass[j] * Eigen::Vector3d(p.x, p.y, p.z);
  }
  mean /= total;
  Eigen::Matrix3d second = Eigen::Matrix3d::Zero();
  GaussianPoint out;
  std::map<std::uint32_t, double> label_mass;
  std::array<double, 3 + 3 * kShRestPerChannel + kFeatureDim + 2> sums{};
  for (std::size_t j = 0; j < indices.size(); ++j) {
    const GaussianPoint& p = cloud[indices[j]];
    const double w = mass[j] / total;
    Eigen::Quaterniond q(p.rot[0], p.rot[1], p.rot[2], p.rot[3]);
    if (!(q.norm() > 0)) q = Eigen::Quaterniond::Identity();
    const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
    const Eigen::Vector3d s(std::exp(2.0 * p.scale[0]), std::exp(2.0 * p.scale[1]),
                            std::exp(2.0 * p.scale[2]));
    const Eigen::Vector3d d = Eigen::Vector3d(p.x, p.y, p.z) - mean;
    second += w * (r * s.asDiagonal() * r.transpose() + d * d.transpose());
    std::size_t k = 0;
    for (int c = 0; c < 3; ++c) sums[k++] += w * p.f_dc[c];
    for (int c = 0; c < 3 * kShRestPerChannel; ++c) sums[k++] += w * p.f_rest[c];
    for (int c = 0; c < kFeatureDim; ++c) sums[k++] += w * p.feature[c];
    sums[k++] += w * p.log_alpha;
    sums[k++] += w * p.confidence;
    label_mass[p.label] += mass[j];
  }
  const Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eigen(second);
  Eigen::Matrix3d axes = eigen.eigenvectors();
  if (axes.determinant() < 0) axes.col(0) = -axes.col(0);
  double sd[3];
  for (int k = 0; k < 3; ++k) {
    sd[k] = std::sqrt(std::max(eigen.eigenvalues()[k], kMinVariance));
    out.scale[k] = static_cast<float>(std::log(sd[k]));
  }
  const double area = sd[0] * sd[1] + sd[0] * sd[2] + sd[1] * sd[2];
  const Eigen::Quaterniond q(axes);
  out.rot[0] = static_cast<float>(q.w());
  out.rot[1] = static_cast<float>(q.x());
  out.rot[2] = static_cast<float>(q.y());
  out.rot[3] = static_cast<float>(q.z());
  const double alpha = std::clamp(total / area, kMinMergedAlpha, kMaxMergedAlpha);
  out.opacity = static_cast<float>(std::log(alpha / (1.0 - alpha)));
  out.x = static_cast<float>(mean.x());
  out.y = static_cast<float>(mean.y());
  out.z = static_cast<float>(mean.z());
  std::size_t k = 0;
  for (int c = 0; c < 3; ++c) out.f_dc[c] = static_cast<float>(sums[k++]);
  for (int c = 0; c < 3 * kShRestPerChannel; ++c) out.f_rest[c] = static_cast<float>(sums[k++]);
  for (int c = 0; c < kFeatureDim; ++c) out.feature[c] = static_cast<float>(sums[k++]);
  out.log_alpha = static_cast<float>(sums[k++]);
  out.confidence = static_cast<float>(sums[k++]);
  out.label = std::max_element(label_mass.begin(), label_mass.end(), [](auto& a, auto& b) {
                return a.second < b.second;
              })->first;
  return out;
}

pcl::PointCloud<GaussianPoint> mergeInVoxels(const pcl::PointCloud<GaussianPoint>& cloud,
                                             const GaussianMergeOptions& options,
                                             std::vector<std::size_t>* group_of) {
  std::size_t groups = 0;
  const std::vector<std::size_t> group = groupInVoxels(cloud, options, &groups);
  std::vector<std::vector<std::size_t>> members(groups);
  for (std::size_t i = 0; i < cloud.size(); ++i) members[group[i]].push_back(i);
  pcl::PointCloud<GaussianPoint> out;
  out.resize(groups);
  for (std::size_t g = 0; g < groups; ++g) out[g] = mergeGaussians(cloud, members[g]);
  out.width = static_cast<std::uint32_t>(groups);
  out.height = 1;
  out.is_dense = true;
  if (group_of != nullptr) *group_of = group;
  return out;
}

std::size_t countVoxelGroups(const pcl::PointCloud<GaussianPoint>& cloud,
                             const GaussianMergeOptions& options) {
  std::size_t groups = 0;
  groupInVoxels(cloud, options, &groups);
  return groups;
}

namespace {

// Cuts `idx` (a range of indices) into `target` groups (see compactGaussians) appended to `groups`.
void splitIntoGroups(const pcl::PointCloud<GaussianPoint>& cloud, std::vector<std::size_t>::iterator first,
                     std::vector<std::size_t>::iterator last, std::size_t target,
                     std::vector<std::pair<std::size_t, std::size_t>>& groups, std::size_t base) {
  const std::size_t n = static_cast<std::size_t>(last - first);
  if (target <= 1 || n <= 1) {
    groups.emplace_back(base, base + n);
    return;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (auto it = first; it != last; ++it) {
    const GaussianPoint& p = cloud[*it];
    const Eigen::Vector3d x(p.x, p.y, p.z);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const std::size_t left_target = target / 2;
  const std::size_t cut = std::clamp<std::size_t>(n * left_target / target, 1, n - 1);
  std::nth_element(first, first + static_cast<std::ptrdiff_t>(cut), last,
                   [&](std::size_t a, std::size_t b) {
                     const float* pa = &cloud[a].x;
                     const float* pb = &cloud[b].x;
                     return pa[axis] < pb[axis] || (pa[axis] == pb[axis] && a < b);
                   });
  const auto middle = first + static_cast<std::ptrdiff_t>(cut);
  splitIntoGroups(cloud, first, middle, left_target, groups, base);
  splitIntoGroups(cloud, middle, last, target - left_target, groups, base + cut);
}

}  // namespace

namespace {

// What the pair cost needs of a Gaussian: covariance, its log-determinant, mass.
struct Moments {
  Eigen::Matrix3d sigma;
  double log_det = 0;
  double mass = 0;
};

Moments momentsOf(const GaussianPoint& p) {
  Eigen::Quaterniond q(p.rot[0], p.rot[1], p.rot[2], p.rot[3]);
  if (!(q.norm() > 0)) q = Eigen::Quaterniond::Identity();
  const Eigen::Matrix3d r = q.normalized().toRotationMatrix();
  const Eigen::Vector3d v(std::exp(2.0 * p.scale[0]) + kMinVariance,
                          std::exp(2.0 * p.scale[1]) + kMinVariance,
                          std::exp(2.0 * p.scale[2]) + kMinVariance);
  Moments m;
  m.sigma = r * v.asDiagonal() * r.transpose();
  m.log_det = std::log(v[0]) + std::log(v[1]) + std::log(v[2]);
  m.mass = massOf(p);
  return m;
}

// The cost of merging a and b: the entropy the moment-matched Gaussian adds over its two parts,
// 0.5 (log det S - p_a log det S_a - p_b log det S_b) (>= 0, independent of the scene's scale:
// near, overlapping pairs of any size are cheap), plus the squared difference of their colour
// (all SH coefficients), as splat-transform's decimation (NanoGS) weighs shape against colour.
double pairCost(const GaussianPoint& a, const Moments& ma, const GaussianPoint& b,
                const Moments& mb) {
  const double total = ma.mass + mb.mass;
  const double pa = total > 0 ? std::clamp(ma.mass / total, 1e-12, 1 - 1e-12) : 0.5;
  const double pb = 1 - pa;
  const Eigen::Vector3d d(double(a.x) - b.x, double(a.y) - b.y, double(a.z) - b.z);
  const Eigen::Matrix3d merged = pa * ma.sigma + pb * mb.sigma + pa * pb * d * d.transpose();
  const double geometric =
      0.5 * (std::log(std::max(merged.determinant(), 1e-300)) - pa * ma.log_det - pb * mb.log_det);
  double colour = 0;
  for (int c = 0; c < 3; ++c) colour += (a.f_dc[c] - b.f_dc[c]) * (a.f_dc[c] - b.f_dc[c]);
  for (int c = 0; c < 3 * kShRestPerChannel; ++c) {
    colour += (a.f_rest[c] - b.f_rest[c]) * (a.f_rest[c] - b.f_rest[c]);
  }
  return geometric + colour;
}

// The merged Gaussians' members' bounding boxes, to say how far a merge reaches.
struct Reach {
  Eigen::Vector3f lo, hi;
  std::size_t members = 1;
};

}  // namespace

CompactResult compactGaussians(const pcl::PointCloud<GaussianPoint>& cloud, std::size_t target,
                               bool class_aware) {
  if (target == 0) throw Error("<compact>", "target count", "at least 1 Gaussian", "0");
  CompactResult result;
  if (cloud.size() <= target) {
    result.cloud = cloud;
    return result;
  }
  std::set<std::uint32_t> labels;
  for (const GaussianPoint& p : cloud) labels.insert(class_aware ? p.label : 0u);
  if (labels.size() > target) {
    throw Error("<compact>", "target count",
                "at least the number of classes present (" + std::to_string(labels.size()) +
                    "): class-aware merging keeps one Gaussian per class",
                std::to_string(target));
  }
  auto current = std::make_shared<pcl::PointCloud<GaussianPoint>>(cloud);
  std::vector<Reach> reach(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    reach[i].lo = reach[i].hi = Eigen::Vector3f(cloud[i].x, cloud[i].y, cloud[i].z);
  }
  int neighbours = 8;
  while (current->size() > target) {
    const std::size_t n = current->size();
    const std::size_t need = n - target;
    std::vector<Moments> moments(n);
    for (std::size_t i = 0; i < n; ++i) moments[i] = momentsOf((*current)[i]);
    pcl::KdTreeFLANN<GaussianPoint> tree;
    tree.setInputCloud(current);
    // Each Gaussian's cheapest partner among its nearest neighbours (of its class).
    std::vector<std::tuple<double, std::size_t, std::size_t>> pairs;
    pairs.reserve(n);
    pcl::Indices found;
    std::vector<float> distances;
    const int k = static_cast<int>(std::min<std::size_t>(n, neighbours + 1));
    for (std::size_t i = 0; i < n; ++i) {
      tree.nearestKSearch((*current)[i], k, found, distances);
      double best = std::numeric_limits<double>::max();
      std::size_t partner = i;
      for (const auto f : found) {
        const std::size_t j = static_cast<std::size_t>(f);
        if (j == i || (class_aware && (*current)[j].label != (*current)[i].label)) continue;
        const double c = pairCost((*current)[i], moments[i], (*current)[j], moments[j]);
        if (c < best) {
          best = c;
          partner = j;
        }
      }
      if (partner != i) pairs.emplace_back(best, std::min(i, partner), std::max(i, partner));
    }
    std::sort(pairs.begin(), pairs.end());
    std::vector<std::size_t> partner_of(n, n);
    std::size_t accepted = 0;
    for (const auto& [cost, a, b] : pairs) {
      if (accepted == need) break;
      if (partner_of[a] != n || partner_of[b] != n) continue;
      partner_of[a] = b;
      partner_of[b] = a;
      ++accepted;
    }
    if (accepted == 0) {
      if (neighbours >= 256) {
        throw Error("<compact>", "target count", "Gaussians with a neighbour of their class to merge",
                    "none left within 256 neighbours");
      }
      neighbours *= 4;  // a class's Gaussians lie apart: look further
      continue;
    }
    auto next = std::make_shared<pcl::PointCloud<GaussianPoint>>();
    next->reserve(n - accepted);
    std::vector<Reach> next_reach;
    next_reach.reserve(n - accepted);
    for (std::size_t i = 0; i < n; ++i) {
      if (partner_of[i] == n) {
        next->push_back((*current)[i]);
        next_reach.push_back(reach[i]);
      } else if (partner_of[i] > i) {
        const std::size_t j = partner_of[i];
        next->push_back(mergeGaussians(*current, {i, j}));
        Reach r;
        r.lo = reach[i].lo.cwiseMin(reach[j].lo);
        r.hi = reach[i].hi.cwiseMax(reach[j].hi);
        r.members = reach[i].members + reach[j].members;
        next_reach.push_back(r);
      }
    }
    current = next;
    reach = std::move(next_reach);
  }
  std::vector<double> extents;
  for (const Reach& r : reach) {
    if (r.members > 1) extents.push_back(static_cast<double>((r.hi - r.lo).norm()));
  }
  if (!extents.empty()) {
    const std::size_t q = std::min(extents.size() - 1, (extents.size() * 9) / 10);
    std::nth_element(extents.begin(), extents.begin() + static_cast<std::ptrdiff_t>(q), extents.end());
    result.group_extent = extents[q];
  }
  result.cloud = std::move(*current);
  result.cloud.width = static_cast<std::uint32_t>(result.cloud.size());
  result.cloud.height = 1;
  result.cloud.is_dense = true;
  return result;
}

}  // namespace filters
}  // namespace sadsplat
