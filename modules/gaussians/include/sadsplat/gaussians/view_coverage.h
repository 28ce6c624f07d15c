#pragma once
/// \file view_coverage.h
/// \brief Where a capture constrains a model: how many cameras see each Gaussian's centre, and
/// the scene extent (3DGS's: from the camera centres). A Gaussian that fewer than two training
/// views see has an unconstrained depth; one far larger than the scene's detail blurs every
/// view it covers. Both are the floaters a user sees from new angles.

#include <ATen/ATen.h>

#include <cstdint>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"

namespace sadsplat {
namespace gaussians {

/// \brief 1.1 times the largest distance of a camera centre from the cameras' mean centre (the
/// 3DGS "cameras extent"; learning rates and size thresholds scale with it). At least 1e-3.
double sceneExtent(const std::vector<RasterCamera>& cameras);

/// \brief Per Gaussian (`means`, [N, 3], any device), how many of `cameras` see its centre: in
/// front of the camera (beyond its near plane) and projecting inside its image. int32 [N], on
/// the device of `means`.
at::Tensor viewCounts(const at::Tensor& means, const std::vector<RasterCamera>& cameras);

/// \brief The camera z of world points (`points`, [N, 3], any device) in `camera`: the depth a
/// render's depth image gives them. double [N] on the device of `points`.
at::Tensor cameraDepths(const at::Tensor& points, const RasterCamera& camera);

/// \brief Which of `points` ([N, 3], world) a camera sees unoccluded, as a view's depth image
/// says: in front of the camera, inside its image, and with their camera z within
/// `relative_tolerance` x z of the depth at their pixel (`depth` [H, W], camera z, e.g. a
/// render's RenderResult::depth; `alpha` [H, W]: pixels below 0.5 show no surface, so nothing
/// there is seen). bool [N] on the device of `points`. A point behind what the image shows is
/// occluded; one in front of it is one the view looks through (not a surface it supports).
at::Tensor seenUnoccluded(const at::Tensor& points, const RasterCamera& camera,
                          const at::Tensor& depth, const at::Tensor& alpha,
                          double relative_tolerance = 0.02);

/// \brief Per pixel of a view rendered through `camera`, how many of `cameras` see the surface
/// point the pixel shows: the pixel's centre back-projected to its expected `depth` ([H, W],
/// camera z, as RenderResult::depth), then counted as viewCounts() counts a centre. int32 [H, W]
/// on the device of `depth`; 0 where `alpha` ([H, W]) is below `min_alpha` (no surface there).
/// What a held-out view can fairly be scored on: pixels whose surface no training view sees are
/// extrapolation, not reconstruction. `stride` > 1 back-projects one pixel per stride x stride
/// block (the one at its centre, rounded down) and gives its count to the whole block: stride^2
/// times less work for large images and many cameras.
/// \throws sadsplat::Error for an orthographic `camera` or shapes that do not match it
at::Tensor pixelViewCounts(const at::Tensor& depth, const at::Tensor& alpha,
                           const RasterCamera& camera, const std::vector<RasterCamera>& cameras,
                           double min_alpha = 0.5, int stride = 1);

/// \brief The scene's sparse points as a float [P, 3] tensor on the CPU, the form the functions
/// below take; undefined when the scene has none.
at::Tensor sparsePointTensor(const io::Scene& scene);

/// \brief A coarse depth image of a view from a scene's sparse points ([P, 3], world): the
/// median camera z of the points that project into each `cell` x `cell` pixel block; blocks
/// without a point take the depth of the nearest block with one. float [H, W] on the CPU, or an
/// undefined tensor when no point lies in front of the camera and inside its image. Depth that
/// belongs to the capture, not to a model: what pixelViewCounts() needs to score models alike.
at::Tensor sparseDepthImage(const at::Tensor& points, const RasterCamera& camera, int cell = 32);

/// \brief Where a camera sees a scene's sparse points, and at what depth: the pixel (row-major
/// index y * W + x of the pixel holding the projection) and camera z of each point in front of the
/// camera and inside its image that is not hidden behind another. A point is hidden when a point
/// of its `cell` x `cell` pixel block lies nearer the camera by more than `relative_tolerance` x
/// its depth (a z-buffer at the sparse points' density: no track of which photos saw a point is
/// needed). `pixels` int64 [K] and `depths` float [K], on the CPU; K = 0 when none is seen.
struct SparseDepthSamples {
  at::Tensor pixels;
  at::Tensor depths;
  std::int64_t size() const { return pixels.defined() ? pixels.size(0) : 0; }
};
SparseDepthSamples visibleSparseDepths(const at::Tensor& points, const RasterCamera& camera,
                                       int cell = 16, double relative_tolerance = 0.03);

/// \brief The floaters of a model: Gaussians seen by fewer than `min_views` cameras, or whose
/// largest scale (standard deviation, world units) exceeds `max_scale`. bool [N] (true = floater).
/// `log_scales` [N, 3] as the trainer stores them. min_views <= 0 or max_scale <= 0 turns that
/// test off.
at::Tensor floaterMask(const at::Tensor& means, const at::Tensor& log_scales,
                       const std::vector<RasterCamera>& cameras, int min_views, double max_scale);

}  // namespace gaussians
}  // namespace sadsplat
