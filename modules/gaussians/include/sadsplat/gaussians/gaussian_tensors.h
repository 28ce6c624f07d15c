#pragma once
/// \file gaussian_tensors.h
/// \brief A set of Gaussians as LibTorch tensors (the trainer's state) and its lossless
/// conversion to and from pcl::PointCloud<sadsplat::GaussianPoint>.

#include <ATen/ATen.h>
#include <pcl/point_cloud.h>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace gaussians {

/// \brief Gaussian parameters as tensors, one row per Gaussian, all on one device.
///
/// Layouts follow the reference 3DGS trainer: SH coefficients are [N, K, 3] (coefficient-major,
/// channels last); the PLY/point type stores f_rest channel-major, and the conversion transposes.
struct GaussianTensors {
  at::Tensor means;          ///< [N, 3] float32
  at::Tensor normals;        ///< [N, 3] float32 (unused by rendering; kept for lossless export)
  at::Tensor sh_dc;          ///< [N, 1, 3] float32
  at::Tensor sh_rest;        ///< [N, 15, 3] float32 (degrees 1..3)
  at::Tensor opacity_logit;  ///< [N] float32
  at::Tensor log_scales;     ///< [N, 3] float32
  at::Tensor rotations;      ///< [N, 4] float32 quaternion (w, x, y, z)
  at::Tensor features;       ///< [N, D] float32 semantic features, D <= kFeatureDim
  at::Tensor log_alpha;      ///< [N] float32 Hard Concrete parameter
  at::Tensor confidence;     ///< [N] float32 semantic confidence
  at::Tensor labels;         ///< [N] int64 class id, -1 = unlabelled

  /// \brief Number of Gaussians (rows of `means`; 0 if undefined).
  std::int64_t size() const { return means.defined() ? means.size(0) : 0; }
  /// \brief Moves (or copies) every tensor to `device`.
  GaussianTensors to(const at::Device& device) const;
  /// \brief Checks shapes, dtypes and devices agree.
  /// \throws sadsplat::Error naming the tensor and the expected shape
  void validate() const;
};

/// \brief Tensors from a cloud, on `device`.
/// \param[in] cloud the Gaussians
/// \param[in] device where the tensors go (CPU or CUDA)
/// \param[in] feature_dim number of feature channels to keep, 0..kFeatureDim
GaussianTensors fromCloud(const pcl::PointCloud<GaussianPoint>& cloud,
                          const at::Device& device = at::kCPU, int feature_dim = kFeatureDim);

/// \brief A cloud from tensors on any device. Features shorter than kFeatureDim are zero-padded.
/// \throws sadsplat::Error if the tensors are inconsistent (see GaussianTensors::validate)
pcl::PointCloud<GaussianPoint> toCloud(const GaussianTensors& tensors);

}  // namespace gaussians
}  // namespace sadsplat
