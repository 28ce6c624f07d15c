#pragma once
// Internal interface between the autograd functions (rasterizer.cpp) and the two backends
// (raster_cpu.cpp, raster_cuda.cu). Both backends implement the same five steps with the math
// of raster_math.h; tensors are contiguous, on the backend's device.

#include <ATen/ATen.h>

#include <array>
#include <tuple>

#include "sadsplat/gaussians/raster_math.h"

namespace sadsplat {
namespace gaussians {
class TileListCapacity;
struct RasterCamera;
namespace raster {

/// A camera as the backends take it (double so that it can be stored in autograd contexts).
struct CameraParams {
  std::array<double, 9> R{};  ///< row-major world-to-camera rotation
  std::array<double, 3> t{};
  double fx = 0, fy = 0, cx = 0, cy = 0;
  int width = 0, height = 0;
  double near_plane = 0.01;
  bool orthographic = false;
};

/// The backends' form of a camera (rasterizer.cpp).
CameraParams cameraParams(const RasterCamera& camera);

struct ProjectionResult {
  at::Tensor means2d;  ///< [N, 2]
  at::Tensor conics;   ///< [N, 3]
  at::Tensor depths;   ///< [N]
  at::Tensor radii;    ///< [N] int32, 0 = culled
};

/// Per-tile lists of Gaussians sorted front to back: tile t uses
/// gaussian_ids[tile_ranges[t, 0] : tile_ranges[t, 1]].
struct Binning {
  at::Tensor tile_ranges;   ///< [tiles_y * tiles_x, 2] int32
  at::Tensor gaussian_ids;  ///< [M] int32
  /// CUDA: gaussian_ids holds the id in its low 24 bits and in the 8 above the warps (two rows
  /// of the tile each) that the Gaussian reaches (fewer than 2^24 Gaussians); never on the CPU
  bool warps_packed = false;
};

/// Closed gates (RenderSettings::closed_gate_gradients): a Gaussian passed with a negative
/// opacity -o is one whose gate is 0 this render. It blends nothing and changes no pixel, but the
/// backends bin it with opacity o, count it in `last` where it would blend, and give it the
/// gradient of the loss with respect to its opacity at 0: per pixel that it would reach with
/// opacity o, G (dot - behind) T + the alpha term, exactly as for a contributor of alpha 0
/// (raster_cpu_tiles.h, unblendClosedGate). Its other gradients are 0. Opacities >= 0 are
/// rendered as always. Both backwards give that gradient only for a RasterResult with
/// closed_gates set (on CUDA a kernel of its own, so that renders without closed gates keep the
/// kernel that has no such branch); without it a closed gate gets no gradient at all.
struct RasterResult {
  at::Tensor image;  ///< [H, W, D] composited channels (no background)
  at::Tensor alpha;  ///< [H, W] accumulated opacity, 1 - final transmittance
  at::Tensor last;   ///< [H, W] int32: 1 + list position of the last contributor, 0 if none
  Binning binning;
  bool closed_gates = false;  ///< the opacities may hold closed gates (above); set by the caller
};

struct ProjectionGrads {
  at::Tensor means, quats, log_scales;
};

struct RasterGrads {
  at::Tensor means2d, conics, opacities, values;
};

/// SH coefficients [N, K, 3] in two parts: the first coefficient `dc` [N, 1, 3] and the others
/// `rest` [N, K - 1, 3] (K = 1: [N, 0, 3]). Unlike the other inputs, each part's rows may lie
/// apart (any stride(0); stride(1) = 3, stride(2) = 1), so the trainer's two parameters, or two
/// narrow views of one [N, K, 3] tensor, are read where they lie: no [N, K, 3] copy per render.
struct ShParts {
  at::Tensor dc, rest;
};

struct ShGrads {
  at::Tensor dc, rest, means;
};

ProjectionResult projectForwardCpu(const at::Tensor& means, const at::Tensor& quats,
                                   const at::Tensor& log_scales, const CameraParams& cam);
ProjectionGrads projectBackwardCpu(const at::Tensor& means, const at::Tensor& quats,
                                   const at::Tensor& log_scales, const at::Tensor& radii,
                                   const CameraParams& cam, const at::Tensor& g_means2d,
                                   const at::Tensor& g_conics, const at::Tensor& g_depths);
/// The CPU rasterizer's tile loops, all with bit-identical results for float: kScalar the scalar
/// reference (raster_cpu_tiles.h), kRows its SSE2 skip test over a tile row, kLanesAvx2 /
/// kLanesAvx512 a tile row's pixels in vector lanes (raster_cpu_lanes.h). kFastest, for float: the
/// AVX2 lanes where they run, else the rows (or what SADSPLAT_CPU_TILE_LOOPS names; double always
/// takes the scalar loops).
enum class CpuTileLoops { kFastest, kScalar, kRows, kLanesAvx2, kLanesAvx512 };

/// Whether `loops` runs here (kScalar and kFastest always do).
bool cpuTileLoopsAvailable(CpuTileLoops loops);

RasterResult rasterizeForwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const at::Tensor& radii, const at::Tensor& depths, int width,
                                 int height, CpuTileLoops loops = CpuTileLoops::kFastest);
RasterGrads rasterizeBackwardCpu(const at::Tensor& means2d, const at::Tensor& conics,
                                 const at::Tensor& opacities, const at::Tensor& values,
                                 const RasterResult& forward, const at::Tensor& g_image,
                                 const at::Tensor& g_alpha,
                                 CpuTileLoops loops = CpuTileLoops::kFastest);

// The CUDA backend takes the stream to run on (a cudaStream_t, as void* so that this header
// needs no CUDA) and expects the tensors' device to be current: the caller, which links LibTorch's
// CUDA libraries, supplies both. The kernels themselves need no c10 CUDA headers, so they also
// compile against a CPU-only LibTorch.
/// SH colours [N, 3] of `sh` seen from `campos` (see raster::shColor); reads the first
/// (degree + 1)^2 coefficients.
at::Tensor shForwardCpu(const ShParts& sh, const at::Tensor& means,
                        const std::array<double, 3>& campos, int degree);
/// Gradients of shForwardCpu for g_colors [N, 3]: contiguous tensors shaped as sh.dc, sh.rest
/// and means, 0 for the coefficients above the degree.
ShGrads shBackwardCpu(const ShParts& sh, const at::Tensor& means,
                      const std::array<double, 3>& campos, int degree, const at::Tensor& g_colors);

#if SADSPLAT_COMPILE_CUDA
ProjectionResult projectForwardCuda(const at::Tensor& means, const at::Tensor& quats,
                                    const at::Tensor& log_scales, const CameraParams& cam,
                                    void* stream);
// g_depths may be undefined (no depth gradient: zeros).
ProjectionGrads projectBackwardCuda(const at::Tensor& means, const at::Tensor& quats,
                                    const at::Tensor& log_scales, const at::Tensor& radii,
                                    const CameraParams& cam, const at::Tensor& g_means2d,
                                    const at::Tensor& g_conics, const at::Tensor& g_depths,
                                    void* stream);
/// capacity: null, or how to size the tile list without waiting for the GPU (tile_list_capacity.h).
RasterResult rasterizeForwardCuda(const at::Tensor& means2d, const at::Tensor& conics,
                                  const at::Tensor& opacities, const at::Tensor& values,
                                  const at::Tensor& radii, const at::Tensor& depths, int width,
                                  int height, TileListCapacity* capacity, void* stream);
// g_alpha may be undefined (no alpha gradient: zeros).
RasterGrads rasterizeBackwardCuda(const at::Tensor& means2d, const at::Tensor& conics,
                                  const at::Tensor& opacities, const at::Tensor& values,
                                  const RasterResult& forward, const at::Tensor& g_image,
                                  const at::Tensor& g_alpha, void* stream);
at::Tensor shForwardCuda(const ShParts& sh, const at::Tensor& means,
                         const std::array<double, 3>& campos, int degree, void* stream);
ShGrads shBackwardCuda(const ShParts& sh, const at::Tensor& means,
                       const std::array<double, 3>& campos, int degree, const at::Tensor& g_colors,
                       void* stream);
#endif

/// The camera in the scalar type of a computation.
template <typename T>
Camera<T> toCamera(const CameraParams& p) {
  Camera<T> c;
  for (int i = 0; i < 9; ++i) c.R[i] = static_cast<T>(p.R[i]);
  for (int i = 0; i < 3; ++i) c.t[i] = static_cast<T>(p.t[i]);
  c.fx = static_cast<T>(p.fx);
  c.fy = static_cast<T>(p.fy);
  c.cx = static_cast<T>(p.cx);
  c.cy = static_cast<T>(p.cy);
  c.width = p.width;
  c.height = p.height;
  c.near_plane = static_cast<T>(p.near_plane);
  c.orthographic = p.orthographic;
  return c;
}

/// Number of tiles along x and y for an image.
inline std::pair<int, int> tileGrid(int width, int height) {
  return {(width + 15) / 16, (height + 15) / 16};
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
