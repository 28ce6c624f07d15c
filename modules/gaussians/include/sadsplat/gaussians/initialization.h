#pragma once
/// \file initialization.h
/// \brief Initial Gaussians from a scene's sparse points (3D Gaussian Splatting's initialisation).

#include <pcl/point_cloud.h>

#include <cstdint>
#include <string>
#include <vector>

#include "sadsplat/common/gaussian_point.h"
#include "sadsplat/gaussians/train_config.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace gaussians {

/// \brief Parameters of the initialisation; defaults are those of the 3DGS reference trainer.
struct InitOptions {
  float initial_opacity = 0.1f;  ///< opacity (not logit) of every Gaussian
  int scale_neighbours = 3;      ///< scale = mean distance to this many nearest neighbours
  float min_scale = 1e-7f;       ///< floor for the distance (duplicate points)
  float feature_stddev = 1e-2f;  ///< semantic features ~ N(0, stddev), seeded
  std::uint64_t seed = 42;
};

/// \brief One isotropic Gaussian per sparse point: centre = point, SH DC from its colour,
/// log-scale = log(mean distance to the k nearest neighbours, through pcl::KdTreeFLANN),
/// identity rotation, opacity logit of `initial_opacity`, small random features, unlabelled.
/// \throws sadsplat::Error if the scene has fewer than scale_neighbours + 1 points
pcl::PointCloud<GaussianPoint> initialCloud(const std::vector<io::ScenePoint>& points,
                                            const InitOptions& options = {});

/// \brief Random points for a scene without sparse points (3DGS initialises synthetic scenes
/// randomly): `count` points on the rays of random pixels of random cameras, at depths uniform
/// in [0.05 h, 2 h] with h = 1.5 x the largest distance of a camera centre from their centroid
/// (h = 1 when the centres coincide), kept only where at least min(2, cameras) of the cameras
/// see them in front of them and inside their image; uniform random colours; seeded.
/// \throws sadsplat::Error when there are no cameras or fewer than 4 such points are found in
/// 200 x count draws
std::vector<io::ScenePoint> randomPointsInView(const std::vector<io::PinholeCamera>& cameras,
                                               int count, std::uint64_t seed);

/// \brief How a training is initialised: points (the scene's sparse points), random
/// (randomPointsInView) or auto (the points when there are at least 4, else random).
/// \throws sadsplat::Error for points with fewer than 4 points
bool initialisesRandomly(InitMode init, std::size_t num_points);

/// \brief SH DC coefficient that renders `rgb` (0..1) at degree 0: (rgb - 0.5) / C0.
float rgbToShDc(float rgb);
/// \brief Inverse of rgbToShDc.
float shDcToRgb(float dc);

}  // namespace gaussians
}  // namespace sadsplat
