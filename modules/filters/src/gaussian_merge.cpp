// Moment-matched merges of Gaussians in voxels (see gaussian_merge.h).
#include "sadsplat/filters/gaussian_merge.h"

#include <Eigen/Dense>
#include <Eigen/Geometry>
#include <algorithm>
#include <cmath>
#include <limits>
#include <map>
#include <string>
#include <unordered_map>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace filters {
namespace {

constexpr double kMaxMergedAlpha = 0.99;
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

}  // namespace

GaussianPoint mergeGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                             const std::vector<std::size_t>& indices) {
  if (indices.empty()) throw Error("<merge>", "indices", "at least one Gaussian", "none");
  if (indices.size() == 1) return cloud[indices[0]];
  std::vector<double> mass(indices.size());
  double total = 0;
  for (std::size_t j = 0; j < indices.size(); ++j) {
    const GaussianPoint& p = cloud[indices[j]];
    mass[j] = sigmoidOf(p.opacity) *
              std::exp(double(p.scale[0]) + double(p.scale[1]) + double(p.scale[2]));
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
  double volume = 1;
  for (int k = 0; k < 3; ++k) {
    const double sd = std::sqrt(std::max(eigen.eigenvalues()[k], kMinVariance));
    out.scale[k] = static_cast<float>(std::log(sd));
    volume *= sd;
  }
  const Eigen::Quaterniond q(axes);
  out.rot[0] = static_cast<float>(q.w());
  out.rot[1] = static_cast<float>(q.x());
  out.rot[2] = static_cast<float>(q.y());
  out.rot[3] = static_cast<float>(q.z());
  const double alpha = std::clamp(total / volume, kMinMergedAlpha, kMaxMergedAlpha);
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

CompactResult compactGaussians(const pcl::PointCloud<GaussianPoint>& cloud, std::size_t target,
                               bool class_aware) {
  if (target == 0) throw Error("<compact>", "target count", "at least 1 Gaussian", "0");
  CompactResult result;
  if (cloud.size() <= target) {
    result.cloud = cloud;
    return result;
  }
  Eigen::Vector3d lo = Eigen::Vector3d::Constant(std::numeric_limits<double>::max());
  Eigen::Vector3d hi = -lo;
  for (const GaussianPoint& p : cloud) {
    const Eigen::Vector3d x(p.x, p.y, p.z);
    lo = lo.cwiseMin(x);
    hi = hi.cwiseMax(x);
  }
  const double extent = std::max((hi - lo).maxCoeff(), 1e-6);
  GaussianMergeOptions o;
  o.class_aware = class_aware;
  double small = extent * 1e-7, large = extent * 2;
  o.voxel_size = large;
  const std::size_t fewest = countVoxelGroups(cloud, o);
  if (fewest > target) {
    throw Error("<compact>", "target count",
                "at least the number of classes present (" + std::to_string(fewest) +
                    "): class-aware merging keeps one Gaussian per class",
                std::to_string(target));
  }
  while (large / small > 1.01) {
    o.voxel_size = std::sqrt(small * large);
    if (countVoxelGroups(cloud, o) <= target) {
      large = o.voxel_size;
    } else {
      small = o.voxel_size;
    }
  }
  o.voxel_size = large;
  result.cloud = mergeInVoxels(cloud, o);
  result.voxel_size = large;
  return result;
}

}  // namespace filters
}  // namespace sadsplat
