#pragma once
/// \file gaussian_merge.h
/// \brief Fewer Gaussians for the same picture: neighbours merged into one by moment matching,
/// as pcl::VoxelGrid merges points into their centroid, but Gaussian for Gaussian and, by
/// default, class for class (a road Gaussian never merges into a roof). The levels of detail of
/// a 3D Tiles tileset and `sadsplat compact` are made with it.
///
/// A group G merges into one Gaussian with the group's masses m_i = alpha_i (s_i0 s_i1 + s_i0 s_i2 +
/// s_i1 s_i2) (opacity times the ellipsoid's footprint area, up to a constant) as weights: centre
/// mu = sum m_i mu_i / M, covariance Sigma = sum m_i (Sigma_i + (mu_i - mu)(mu_i - mu)^T) / M (the
/// second moment of the mixture), its eigenvectors the rotation and the square roots of its
/// eigenvalues the scales; opacity M / (s0 s1 + s0 s2 + s1 s2) (the mass kept), at most 0.999;
/// colour (all SH), feature, gate and confidence the m-weighted means; label the group's (or, not
/// class-aware, the label of the largest mass).
/// A group of one is kept bit for bit.

#include <pcl/point_cloud.h>

#include <cstddef>
#include <cstdint>
#include <vector>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace filters {

/// \brief How Gaussians are grouped for merging.
struct GaussianMergeOptions {
  double voxel_size = 1.0;  ///< edge of the cubic cells (scene units) whose Gaussians merge
  bool class_aware = true;  ///< only Gaussians of one label merge
};

/// \brief One Gaussian with the moments of `indices` of `cloud` (see the file comment).
/// \throws sadsplat::Error when `indices` is empty
GaussianPoint mergeGaussians(const pcl::PointCloud<GaussianPoint>& cloud,
                             const std::vector<std::size_t>& indices);

/// \brief Merges the Gaussians of each voxel (and label): one Gaussian per non-empty cell, in the
/// order of each cell's first Gaussian.
/// \param[out] group_of if not null, for every input Gaussian the index of its output Gaussian
/// \throws sadsplat::Error when voxel_size is not positive and finite
pcl::PointCloud<GaussianPoint> mergeInVoxels(const pcl::PointCloud<GaussianPoint>& cloud,
                                             const GaussianMergeOptions& options,
                                             std::vector<std::size_t>* group_of = nullptr);

/// \brief The number of Gaussians mergeInVoxels would return (without merging).
std::size_t countVoxelGroups(const pcl::PointCloud<GaussianPoint>& cloud,
                             const GaussianMergeOptions& options);

/// \brief The result of compactGaussians.
struct CompactResult {
  pcl::PointCloud<GaussianPoint> cloud;
  /// the 90th percentile over the merged Gaussians of their members' centres' bounding-box
  /// diagonal (scene units): how far a merged Gaussian stands for its members (0: none merged)
  double group_extent = 0;
};

/// \brief Exactly `target` Gaussians (the cloud unchanged when it has no more), by rounds of
/// pairwise merges: each Gaussian's cheapest partner among its 8 nearest neighbours of its class
/// (class-aware), the cheapest disjoint pairs merged until the count is reached (at most halving
/// per round; the search widens when no pair is left). The cost of a pair: the entropy its
/// moment-matched merge adds, 0.5 (log det Sigma - p_i log det Sigma_i - p_j log det Sigma_j),
/// plus the squared difference of their SH colour (as splat-transform's decimation weighs them).
/// \throws sadsplat::Error when `target` is 0 or below the number of labels (class-aware)
CompactResult compactGaussians(const pcl::PointCloud<GaussianPoint>& cloud, std::size_t target,
                               bool class_aware = true);

}  // namespace filters
}  // namespace sadsplat
