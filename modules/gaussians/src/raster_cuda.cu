// The CUDA backend of the rasterizer: the same five steps as raster_cpu.cpp, with the math of
// raster_math.h, as tile-based kernels in the manner of the reference 3DGS rasterizer. Runs on
// LibTorch's current stream; float32 only.
#include <ATen/ATen.h>

#include <cuda_runtime.h>
#include <cub/device/device_radix_sort.cuh>

#include <cstdlib>
#include <limits>
#include <string>
#include <tuple>

#include "raster_backend.h"
#include "sadsplat/common/cuda_support.h"
#include "sadsplat/gaussians/raster_math.h"
#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/tile_list_capacity.h"
#include "tf32_mma.cuh"

namespace sadsplat {
namespace gaussians {
namespace raster {
namespace {

constexpr int kBlock = kTileSize * kTileSize;  // threads per tile block
constexpr int kThreads1d = 256;

void check(const at::Tensor& t, const char* name) {
  if (!t.is_cuda() || t.scalar_type() != at::kFloat || !t.is_contiguous()) {
    throw Error("<render>", name, "a contiguous float32 CUDA tensor",
                std::string(c10::toString(t.scalar_type())) + " on " + t.device().str());
  }
}

// An SH part (ShParts): rows of 3-float coefficients, the rows any distance apart.
void checkShPart(const at::Tensor& t, const char* name) {
  if (!t.is_cuda() || t.scalar_type() != at::kFloat || t.dim() != 3 || t.size(2) != 3 ||
      t.stride(2) != 1 || (t.size(1) > 1 && t.stride(1) != 3)) {
    throw Error("<render>", name, "a float32 CUDA tensor [N, K, 3] of row-major rows",
                std::string(c10::toString(t.scalar_type())) + " on " + t.device().str());
  }
}

void checkLaunch(const char* kernel) { checkCudaLaunch("<render>", kernel); }

int blocksFor(int64_t n) { return static_cast<int>((n + kThreads1d - 1) / kThreads1d); }

// ---- projection ------------------------------------------------------------------------------

__global__ void projectForwardKernel(int64_t n, const float* __restrict__ means,
                                     const float* __restrict__ quats,
                                     const float* __restrict__ log_scales, Camera<float> cam,
                                     float* means2d, float* conics, float* depths, int* radii) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  Projected<float> p;
  if (!projectGaussian(means + 3 * i, quats + 4 * i, log_scales + 3 * i, cam, &p)) {
    // Every output written (they are allocated without a fill).
    means2d[2 * i] = means2d[2 * i + 1] = 0.f;
    conics[3 * i] = conics[3 * i + 1] = conics[3 * i + 2] = 0.f;
    depths[i] = 0.f;
    radii[i] = 0;
    return;
  }
  means2d[2 * i] = p.mean2d[0];
  means2d[2 * i + 1] = p.mean2d[1];
  conics[3 * i] = p.conic[0];
  conics[3 * i + 1] = p.conic[1];
  conics[3 * i + 2] = p.conic[2];
  depths[i] = p.depth;
  radii[i] = p.radius;
}

__global__ void projectBackwardKernel(
    int64_t n, const float* __restrict__ means, const float* __restrict__ quats,
    const float* __restrict__ log_scales, const int* __restrict__ radii, Camera<float> cam,
    const float* __restrict__ g_means2d, const float* __restrict__ g_conics,
    const float* __restrict__ g_depths, float* g_means, float* g_quats, float* g_log_scales) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  // The gradients are allocated without a fill: every row starts at zero here, and
  // projectGaussianBackward adds to it. g_depths may be null (no depth gradient).
  float g_mean[3] = {0.f, 0.f, 0.f}, g_quat[4] = {0.f, 0.f, 0.f, 0.f};
  float g_log_scale[3] = {0.f, 0.f, 0.f};
  if (radii[i] > 0) {
    projectGaussianBackward(means + 3 * i, quats + 4 * i, log_scales + 3 * i, cam,
                            g_means2d + 2 * i, g_conics + 3 * i,
                            g_depths != nullptr ? g_depths[i] : 0.f, g_mean, g_quat, g_log_scale);
  }
  for (int k = 0; k < 3; ++k) g_means[3 * i + k] = g_mean[k];
  for (int k = 0; k < 4; ++k) g_quats[4 * i + k] = g_quat[k];
  for (int k = 0; k < 3; ++k) g_log_scales[3 * i + k] = g_log_scale[k];
}

// ---- spherical harmonics ---------------------------------------------------------------------

// One thread per Gaussian, kShBlock Gaussians per block. A Gaussian's coefficients are a row of
// 3 (degree + 1)^2 floats (192 bytes at degree 3) in two parts (dc, rest); read or written a
// thread per row, a warp's access would touch 32 rows at once. The block's rows go through
// shared memory instead, copied with consecutive threads on consecutive floats. Shared rows are
// kShStride (odd) floats apart, so the 32 threads of a warp, each on its own row, hit 32
// different banks.
constexpr int kShBlock = 64;
constexpr int kShMaxRow = 16 * 3;  // degree 3
constexpr int kShStride = kShMaxRow + 1;

// A row of `used` coefficients of Gaussian i: the first from dc, the others from rest (each
// part's rows `*_stride` floats apart, raster_backend.h's ShParts).
struct ShRows {
  const float* __restrict__ dc;
  const float* __restrict__ rest;
  int64_t dc_stride, rest_stride;
};

__device__ __forceinline__ void copyShRowsIn(const ShRows& sh, int64_t first, int rows,
                                             int row_len, float* s_rows) {
  for (int e = threadIdx.x; e < rows * row_len; e += blockDim.x) {
    const int64_t i = first + e / row_len;
    const int c = e % row_len;
    s_rows[(e / row_len) * kShStride + c] =
        c < 3 ? sh.dc[i * sh.dc_stride + c] : sh.rest[i * sh.rest_stride + c - 3];
  }
}

__global__ void __launch_bounds__(kShBlock)
    shForwardKernel(int64_t n, int used, int degree, float3 campos, ShRows sh,
                    const float* __restrict__ means, float* colors) {
  __shared__ float s_sh[kShBlock * kShStride];
  const int64_t first = static_cast<int64_t>(blockIdx.x) * kShBlock;
  const int rows = static_cast<int>(min(static_cast<int64_t>(kShBlock), n - first));
  copyShRowsIn(sh, first, rows, 3 * used, s_sh);
  __syncthreads();
  if (static_cast<int>(threadIdx.x) >= rows) return;
  const int64_t i = first + threadIdx.x;
  const float cam[3] = {campos.x, campos.y, campos.z};
  shColor(s_sh + threadIdx.x * kShStride, degree, means + 3 * i, cam, colors + 3 * i);
}

// Writes the gradients of the `used` coefficients (g_dc [N, 1, 3] and the first used - 1 of
// g_rest's rest_row / 3 per Gaussian, both contiguous); the others are the caller's to clear.
__global__ void __launch_bounds__(kShBlock)
    shBackwardKernel(int64_t n, int used, int degree, float3 campos, ShRows sh,
                     const float* __restrict__ means, const float* __restrict__ g_colors,
                     float* g_dc, float* g_rest, int64_t rest_row, float* g_means) {
  __shared__ float s_sh[kShBlock * kShStride];
  __shared__ float s_g_sh[kShBlock * kShStride];
  const int64_t first = static_cast<int64_t>(blockIdx.x) * kShBlock;
  const int rows = static_cast<int>(min(static_cast<int64_t>(kShBlock), n - first));
  const int row_len = 3 * used;
  copyShRowsIn(sh, first, rows, row_len, s_sh);
  for (int e = threadIdx.x; e < kShBlock * kShStride; e += blockDim.x) s_g_sh[e] = 0.f;
  __syncthreads();
  if (static_cast<int>(threadIdx.x) < rows) {
    const int64_t i = first + threadIdx.x;
    const float cam[3] = {campos.x, campos.y, campos.z};
    shColorBackward(s_sh + threadIdx.x * kShStride, degree, means + 3 * i, cam, g_colors + 3 * i,
                    s_g_sh + threadIdx.x * kShStride, g_means + 3 * i);
  }
  __syncthreads();
  for (int e = threadIdx.x; e < rows * row_len; e += blockDim.x) {
    const int64_t i = first + e / row_len;
    const int c = e % row_len;
    const float v = s_g_sh[(e / row_len) * kShStride + c];
    if (c < 3) {
      g_dc[3 * i + c] = v;
    } else {
      g_rest[i * rest_row + c - 3] = v;
    }
  }
}

int shBlocksFor(int64_t n) { return static_cast<int>((n + kShBlock - 1) / kShBlock); }

ShRows shRows(const ShParts& sh) {
  return {sh.dc.data_ptr<float>(), sh.rest.data_ptr<float>(), sh.dc.stride(0),
          sh.rest.stride(0)};
}

// ---- binning ---------------------------------------------------------------------------------

// Bits of the warps of a tile row ty (warp w: pixel centres ty * 16 + 2 w + 0.5 and + 1.5) whose
// rows meet [y0, y1]: from the warp whose second row reaches y0 to the one whose first row is
// within y1. A list entry carries them (packWarps) so that a warp skips a Gaussian without its
// bit before any pixel work: each of its pixels would get alpha 0.
__device__ __forceinline__ unsigned warpsOfRows(float y0, float y1, int ty) {
  const float first_row = ty * kTileSize + 0.5f;
  const float lo = fminf(fmaxf((y0 - first_row - 1.f) * 0.5f, -1.f), 8.f);
  const float hi = fminf(fmaxf((y1 - first_row) * 0.5f, -1.f), 8.f);
  const int w0 = max(static_cast<int>(ceilf(lo)), 0);
  const int w1 = min(static_cast<int>(floorf(hi)), kBlock / 32 - 1);
  return w1 < w0 ? 0u : ((2u << w1) - 1u) & ~((1u << w0) - 1u);
}

// Gaussian ids below 2^24 leave a list entry's value 8 bits for its warps.
constexpr int kIdBits = 24;
constexpr int64_t kMaxPackedGaussians = int64_t{1} << kIdBits;

// Whether a render of n Gaussians packs the warp bits: below 2^24 Gaussians, unless the
// environment variable SADSPLAT_CUDA_WARP_BITS is 0 (every warp then takes every entry, as above
// 2^24: for testing that path and for timing; any other value than 0 or 1 is an error).
// Read at every render (a getenv per render), so that a test can switch it.
bool packsWarpBits(int64_t n) {
  const char* env = std::getenv("SADSPLAT_CUDA_WARP_BITS");
  if (env != nullptr && *env != '\0') {
    const std::string v = env;
    if (v != "0" && v != "1") throw Error("SADSPLAT_CUDA_WARP_BITS", "value", "0 or 1", v);
    if (v == "0") return false;
  }
  return n <= kMaxPackedGaussians;
}

// A list entry's value: the Gaussian's id, and where ids fit in 24 bits the warps its ellipse
// reaches in the 8 bits above (the sort carries them for free); with more Gaussians every warp
// takes every entry.
__device__ __forceinline__ int packWarps(int64_t id, unsigned warps, bool packed) {
  return packed ? static_cast<int>(static_cast<unsigned>(id) | (warps << kIdBits))
                : static_cast<int>(id);
}

__global__ void countTilesKernel(int64_t n, const float* __restrict__ means2d,
                                 const float* __restrict__ conics, const int* __restrict__ radii,
                                 const float* __restrict__ opacities, int tiles_x, int tiles_y,
                                 int64_t* counts) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  int64_t count = 0;
  const float opacity = fabsf(opacities[i]);  // a closed gate's (raster_backend.h) as if open
  AlphaEllipse<float> ellipse;
  int rx = 0, ry = 0;
  if (alphaEllipse(means2d + 2 * i, conics + 3 * i, opacity, &ellipse)) {
    alphaBox(radii[i], ellipse, &rx, &ry);
  }
  if (rx > 0) {
    int x0, y0, x1, y1;
    tileRect(means2d + 2 * i, rx, ry, tiles_x, tiles_y, &x0, &y0, &x1, &y1);
    for (int ty = y0; ty < y1; ++ty) {
      for (int tx = x0; tx < x1; ++tx) count += alphaEllipseMeetsTile(ellipse, tx, ty);
    }
  }
  counts[i] = count;
}

// Key = tile id (high 32 bits) | depth's float bits (positive floats sort like their bits).
__global__ void writeKeysKernel(int64_t n, const float* __restrict__ means2d,
                                const float* __restrict__ conics, const int* __restrict__ radii,
                                const float* __restrict__ opacities,
                                const float* __restrict__ depths,
                                const int64_t* __restrict__ offsets, int tiles_x, int tiles_y,
                                int64_t capacity, bool pack_warps, int64_t* keys,
                                int* values) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= n) return;
  int64_t out = i == 0 ? 0 : offsets[i - 1];
  const int64_t end = min(offsets[i], capacity);  // a list sized before the count may end early
  const float opacity = fabsf(opacities[i]);  // a closed gate's (raster_backend.h) as if open
  AlphaEllipse<float> ellipse;
  int rx = 0, ry = 0;
  if (alphaEllipse(means2d + 2 * i, conics + 3 * i, opacity, &ellipse)) {
    alphaBox(radii[i], ellipse, &rx, &ry);
  }
  if (rx > 0) {
    int x0, y0, x1, y1;
    tileRect(means2d + 2 * i, rx, ry, tiles_x, tiles_y, &x0, &y0, &x1, &y1);
    const int64_t depth_bits = static_cast<int64_t>(__float_as_uint(depths[i]));
    for (int tx = x0; tx < x1 && out < end; ++tx) {
      // The rows the ellipse reaches within this tile column, for the entries' warp bits.
      const float column = tx * kTileSize + 0.5f;
      float rows0 = 0.f, rows1 = 0.f;
      if (!alphaEllipseRows(ellipse, column, column + float(kTileSize - 1), &rows0, &rows1)) {
        rows0 = rows1 = -1e30f;  // no row; the tile test below then fails as well
      }
      for (int ty = y0; ty < y1 && out < end; ++ty) {
        if (!alphaEllipseMeetsTile(ellipse, tx, ty)) continue;
        keys[out] = (static_cast<int64_t>(ty * tiles_x + tx) << 32) | depth_bits;
        values[out] = packWarps(i, warpsOfRows(rows0, rows1, ty), pack_warps);
        ++out;
      }
    }
  }
  // The count kernel made the same tests, so nothing is left; should a test ever come out
  // otherwise here (the compiler may contract its float operations differently in the two
  // kernels), the rest gets tile num_tiles' key: sorted last, in no tile's range.
  for (; out < end; ++out) {
    keys[out] = static_cast<int64_t>(tiles_x * tiles_y) << 32;
    values[out] = 0;
  }
}

// Entries of a tile id >= num_tiles are the unused end of a list sized before the count.
__global__ void tileRangesKernel(int64_t m, const int64_t* __restrict__ keys, int num_tiles,
                                 int* ranges) {
  const int64_t i = blockIdx.x * static_cast<int64_t>(blockDim.x) + threadIdx.x;
  if (i >= m) return;
  const int tile = static_cast<int>(keys[i] >> 32);
  if (tile >= num_tiles) return;
  if (i == 0 || static_cast<int>(keys[i - 1] >> 32) != tile) ranges[2 * tile] = static_cast<int>(i);
  if (i == m - 1 || static_cast<int>(keys[i + 1] >> 32) != tile) {
    ranges[2 * tile + 1] = static_cast<int>(i + 1);
  }
}

// Sorts the (key, Gaussian id) pairs by key with a radix sort over the key's used bits only: the
// 32 depth bits and as many tile bits as the tile count needs (11 at 800x450), not all 64. A
// radix sort is stable: equal keys (same tile and depth) keep Gaussian id order, as on the CPU.
// `tile_ids`: how many tile ids the keys hold (the tiles, and one more for a list's unused end).
std::pair<at::Tensor, at::Tensor> sortByTileAndDepth(const at::Tensor& keys,
                                                     const at::Tensor& values, int tile_ids,
                                                     cudaStream_t stream) {
  const int64_t m = keys.size(0);
  if (m > std::numeric_limits<int>::max()) {
    throw Error("<render>", "tile entries", "at most 2^31 - 1 (Gaussian, tile) pairs",
                std::to_string(m) + " (fewer Gaussians or a smaller image)");
  }
  int tile_bits = 1;
  while ((int64_t{1} << tile_bits) < tile_ids) ++tile_bits;
  const int end_bit = 32 + tile_bits;
  using Key = unsigned long long;  // keys are non-negative: the unsigned order is the same
  const auto* keys_in = reinterpret_cast<const Key*>(keys.data_ptr<int64_t>());
  at::Tensor sorted_keys = at::empty({m}, keys.options()),
             sorted_values = at::empty({m}, values.options());
  auto* keys_out = reinterpret_cast<Key*>(sorted_keys.data_ptr<int64_t>());
  std::size_t temp_bytes = 0;
  cub::DeviceRadixSort::SortPairs(nullptr, temp_bytes, keys_in, keys_out, values.data_ptr<int>(),
                                  sorted_values.data_ptr<int>(), static_cast<int>(m), 0, end_bit,
                                  stream);
  at::Tensor temp = at::empty({static_cast<int64_t>(temp_bytes)}, keys.options().dtype(at::kByte));
  const cudaError_t err = cub::DeviceRadixSort::SortPairs(
      temp.data_ptr(), temp_bytes, keys_in, keys_out, values.data_ptr<int>(),
      sorted_values.data_ptr<int>(), static_cast<int>(m), 0, end_bit, stream);
  if (err != cudaSuccess) {
    throw Error("<render>", "radix sort", "a successful sort", cudaGetErrorString(err));
  }
  return {sorted_keys, sorted_values};
}

// The (Gaussian, tile) list of one render: count each Gaussian's tiles, write the keys at the
// counts' running sum, sort, and mark each tile's range. The list's length is the total count,
// read from the GPU (the host waits for the queue); with a capacity that knows earlier counts,
// the list has capacity->capacity() entries instead and nobody waits: entries past the count
// keep the key of tile num_tiles (sorted last, in no tile's range), pairs past the capacity are
// not written, and the count goes to the host for capacity->renderedAll() to check.
Binning binGaussians(const at::Tensor& means2d, const at::Tensor& conics, const at::Tensor& radii,
                     const at::Tensor& opacities, const at::Tensor& depths, int width, int height,
                     TileListCapacity* capacity, cudaStream_t stream) {
  const int64_t n = means2d.size(0);
  const ScopedPhase phase("binning");
  const auto [tiles_x, tiles_y] = tileGrid(width, height);
  const int num_tiles = tiles_x * tiles_y;
  const auto opts = means2d.options();
  Binning b;
  b.warps_packed = packsWarpBits(n);
  b.tile_ranges = at::empty({num_tiles, 2}, opts.dtype(at::kInt));  // tiles without entries: 0, 0
  cudaMemsetAsync(b.tile_ranges.data_ptr<int>(), 0, 2 * sizeof(int) * num_tiles, stream);
  checkLaunch("cudaMemsetAsync of the tile ranges");
  if (n == 0) {
    b.gaussian_ids = at::empty({0}, opts.dtype(at::kInt));
    return b;
  }
  at::Tensor counts = at::empty({n}, opts.dtype(at::kLong));
  countTilesKernel<<<blocksFor(n), kThreads1d, 0, stream>>>(
      n, means2d.data_ptr<float>(), conics.data_ptr<float>(), radii.data_ptr<int>(),
      opacities.data_ptr<float>(), tiles_x, tiles_y, counts.data_ptr<int64_t>());
  checkLaunch("countTilesKernel");
  const at::Tensor offsets = counts.cumsum(0);
  const bool sized_before = capacity != nullptr && capacity->capacity() > 0;
  int64_t m = 0;
  at::Tensor keys, values;
  if (sized_before) {
    m = capacity->capacity();
    const TileListCapacity::Slot slot = capacity->reserve();
    cudaError_t err = cudaMemcpyAsync(slot.count, offsets.data_ptr<int64_t>() + (n - 1),
                                      sizeof(int64_t), cudaMemcpyDeviceToHost, stream);
    if (err == cudaSuccess) err = cudaEventRecord(static_cast<cudaEvent_t>(slot.event), stream);
    if (err != cudaSuccess) {
      throw Error("<render>", "tile count", "queued for the host", cudaGetErrorString(err));
    }
    keys = at::full({m}, static_cast<int64_t>(num_tiles) << 32, opts.dtype(at::kLong));
  } else {
    m = offsets[n - 1].item<int64_t>();
    if (capacity != nullptr) capacity->counted(m);
    keys = at::empty({m}, opts.dtype(at::kLong));
  }
  values = at::empty({m}, opts.dtype(at::kInt));
  if (m > 0) {
    writeKeysKernel<<<blocksFor(n), kThreads1d, 0, stream>>>(
        n, means2d.data_ptr<float>(), conics.data_ptr<float>(), radii.data_ptr<int>(),
        opacities.data_ptr<float>(), depths.data_ptr<float>(), offsets.data_ptr<int64_t>(), tiles_x,
        tiles_y, m, b.warps_packed, keys.data_ptr<int64_t>(), values.data_ptr<int>());
    checkLaunch("writeKeysKernel");
    const ScopedPhase sort_phase("sort");
    std::tie(keys, values) = sortByTileAndDepth(keys, values, num_tiles + 1, stream);
    tileRangesKernel<<<blocksFor(m), kThreads1d, 0, stream>>>(
        m, keys.data_ptr<int64_t>(), num_tiles, b.tile_ranges.data_ptr<int>());
    checkLaunch("tileRangesKernel");
  }
  b.gaussian_ids = values;
  return b;
}

// ---- rasterization ---------------------------------------------------------------------------



// Copies list entry k into this thread's slot of the block's shared batch: its Gaussian's 2D
// data and the warps it reaches (packWarps).
__device__ __forceinline__ void stageGaussian(int k, const int* __restrict__ ids,
                                              bool warps_packed,
                                              const float* __restrict__ means2d,
                                              const float* __restrict__ conics,
                                              const float* __restrict__ opacities, int* s_id,
                                              float (*s_mean)[2], float (*s_conic)[3],
                                              float* s_opacity, unsigned char* s_warps) {
  const int slot = threadIdx.x;
  const unsigned v = static_cast<unsigned>(ids[k]);
  const int g = warps_packed ? static_cast<int>(v & ((1u << kIdBits) - 1u)) : static_cast<int>(v);
  s_id[slot] = g;
  s_mean[slot][0] = means2d[2 * g];
  s_mean[slot][1] = means2d[2 * g + 1];
  s_conic[slot][0] = conics[3 * g];
  s_conic[slot][1] = conics[3 * g + 1];
  s_conic[slot][2] = conics[3 * g + 2];
  s_opacity[slot] = opacities[g];
  s_warps[slot] = static_cast<unsigned char>(warps_packed ? v >> kIdBits : 0xffu);
}

// ---- forward

// Whether the forward stages the batch's values (CH floats per Gaussian, zero padded) in shared
// memory beside its 2D data: up to 36 channels (36 KiB per block). Every pixel that a Gaussian
// reaches reads all its channels; from shared memory that is CH / 4 16-byte loads which all
// threads share, instead of CH loads through the L1 cache (the forward's main stall at 36
// channels, Nsight Compute, H100). Wider values stay in global memory (the shared memory would
// cost more occupancy than the loads).
constexpr bool forwardStagesValues(int CH) { return CH <= 36; }

// Whether the kernels move a warp's two image rows (2 x 16 x D contiguous floats) between global
// and shared memory with consecutive lanes on consecutive floats, instead of each pixel its own D
// floats (D apart from the next lane's: up to 8 times the sectors). From 16 channels on; not for
// RGB, where per-pixel accesses waste less and the copy's registers would cost occupancy.
constexpr bool copiesWarpRows(int CH) { return CH >= 16; }

// The walk of those copies: calls visit(i, k, pixel, c) for each float that lane `lane` moves of
// warp `warp`'s two image rows of tile (tx, ty) — i its index in the [H, W, D] image, k its index
// in the warp's 2 x 16 x D floats, and with kPixels its pixel (0 .. 31) and channel (k = pixel *
// D + c; float e = lane + 32 j of a row is pixel e / D, channel e % D, tracked without a division;
// without kPixels both are 0 and nothing is tracked). Consecutive lanes take consecutive floats.
template <bool kPixels, typename Visit>
__device__ __forceinline__ void forEachWarpRowFloat(int tx, int ty, int warp, int lane, int width,
                                                    int height, int D, Visit&& visit) {
  const int x0 = tx * kTileSize;
  const int row_floats = min(kTileSize, width - x0) * D;
  for (int r = 0; r < 2; ++r) {
    const int y = ty * kTileSize + 2 * warp + r;
    if (y >= height) break;
    const int64_t row_start = (static_cast<int64_t>(y) * width + x0) * D;
    int col = kPixels ? lane / D : 0, c = kPixels ? lane % D : 0;
    for (int e = lane; e < row_floats; e += 32) {
      visit(row_start + e, r * kTileSize * D + e, r * kTileSize + col, c);
      if constexpr (kPixels) {
        for (c += 32; c >= D; c -= D) ++col;
      }
    }
  }
}

// One block per tile, one thread per pixel; Gaussians are staged through shared memory in
// batches of kBlock. CH is the channel capacity (>= D), fixed at compile time so the per-pixel
// accumulators can live in registers.
template <int CH>
__global__ void __launch_bounds__(kBlock)
    rasterizeForwardKernel(int width, int height, int tiles_x, int D,
                           const int* __restrict__ ranges, const int* __restrict__ ids,
                           bool warps_packed,
                           const float* __restrict__ means2d, const float* __restrict__ conics,
                           const float* __restrict__ opacities, const float* __restrict__ values,
                           float* image, float* alpha_out, int* last_out) {
  const int tile = blockIdx.x;
  const int tx = tile % tiles_x, ty = tile / tiles_x;
  const int px = tx * kTileSize + threadIdx.x % kTileSize;
  const int py = ty * kTileSize + threadIdx.x / kTileSize;
  const bool inside = px < width && py < height;
  const float fx = px + 0.5f, fy = py + 0.5f;
  const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];

  __shared__ int s_id[kBlock];
  __shared__ float s_mean[kBlock][2];
  __shared__ float s_conic[kBlock][3];
  __shared__ float s_opacity[kBlock];
  __shared__ unsigned char s_warps[kBlock];
  const int warp_bit = 1 << (threadIdx.x / 32);
  constexpr bool kStaged = forwardStagesValues(CH);
  static_assert(!kStaged || CH % 4 == 0, "staged values are read as whole float4s");
  __shared__ __align__(16) float s_values[kStaged ? kBlock : 1][kStaged ? CH : 4];

  float acc[CH];
#pragma unroll
  for (int c = 0; c < CH; ++c) acc[c] = 0.f;
  float trans = 1.f;
  int last = 0;
  bool done = !inside;
  for (int batch = start; batch < stop; batch += kBlock) {
    if (__syncthreads_count(done) == kBlock) break;
    const int k = batch + threadIdx.x;
    if (k < stop) {
      stageGaussian(k, ids, warps_packed, means2d, conics, opacities, s_id, s_mean, s_conic,
                    s_opacity, s_warps);
      if constexpr (kStaged) {
        const int g = s_id[threadIdx.x];
        const float* src = values + static_cast<int64_t>(g) * D;
#pragma unroll
        for (int q = 0; q < CH / 4; ++q) {
          const int c = 4 * q;
          *reinterpret_cast<float4*>(&s_values[threadIdx.x][c]) = make_float4(
              c < D ? __ldg(src + c) : 0.f, c + 1 < D ? __ldg(src + c + 1) : 0.f,
              c + 2 < D ? __ldg(src + c + 2) : 0.f, c + 3 < D ? __ldg(src + c + 3) : 0.f);
        }
      }
    }
    __syncthreads();
    const int count = min(kBlock, stop - batch);
    for (int j = 0; j < count && !done; ++j) {
      if (!(s_warps[j] & warp_bit)) continue;  // warp-uniform: no pixel of the warp is reached
      float G = 0.f;
      bool clamped;
      const float alpha = pixelAlpha(s_mean[j], s_conic[j], s_opacity[j], fx, fy, &G, &clamped);
      if (alpha == 0.f) {
        // A closed gate it would blend at counts in `last`: the backward visits it there.
        if (closedGateReaches(s_opacity[j], G)) last = batch + j - start + 1;
        continue;
      }
      const float next = trans * (1.f - alpha);
      if (next < float(kMinTransmittance)) {
        done = true;
        break;
      }
      const float w = alpha * trans;
      if constexpr (kStaged) {
#pragma unroll
        for (int q = 0; q < CH / 4; ++q) {
          const float4 v = *reinterpret_cast<const float4*>(&s_values[j][4 * q]);
          if (4 * q < D) acc[4 * q] += w * v.x;
          if (4 * q + 1 < D) acc[4 * q + 1] += w * v.y;
          if (4 * q + 2 < D) acc[4 * q + 2] += w * v.z;
          if (4 * q + 3 < D) acc[4 * q + 3] += w * v.w;
        }
      } else {
        const float* v = values + static_cast<int64_t>(s_id[j]) * D;
#pragma unroll
        for (int c = 0; c < CH; ++c) {
          if (c < D) acc[c] += w * v[c];
        }
      }
      trans = next;
      last = batch + j - start + 1;
    }
  }
  // The channels leave through shared memory (copiesWarpRows), reusing the staged values' space.
  constexpr bool kRowStores = kStaged && copiesWarpRows(CH);
  if constexpr (kRowStores) {
    __syncthreads();  // every warp is past its last read of the batch's values
    const int lane = threadIdx.x % 32, warp = threadIdx.x / 32;
    float* s_out = &s_values[0][0] + warp * 32 * D;  // [pixel of the warp][D]
#pragma unroll
    for (int c = 0; c < CH; ++c) {
      if (c < D) s_out[lane * D + c] = acc[c];
    }
    __syncwarp();
    forEachWarpRowFloat<false>(tx, ty, warp, lane, width, height, D,
                               [&](int64_t i, int k, int, int) { image[i] = s_out[k]; });
  }
  if (!inside) return;
  const int64_t pix = static_cast<int64_t>(py) * width + px;
  if constexpr (!kRowStores) {
#pragma unroll
    for (int c = 0; c < CH; ++c) {
      if (c < D) image[pix * D + c] = acc[c];
    }
  }
  alpha_out[pix] = 1.f - trans;
  last_out[pix] = last;
}

// ---- backward

// One block per 16 x 16 tile, one thread per pixel; Gaussians are staged through
// shared memory in batches of kBlock and every thread visits them in the same order, back to
// front. A warp holds two rows of its tile (32 pixels) and takes a batch in groups of 32
// Gaussians:
//  1. lane l tests whether Gaussian l of the group reaches the warp's 16 x 2 pixels at all (its
//     entry's warp bit, packWarps) and lies before the last contributor of one of its pixels; the ballot is
//     the group's mask, and a Gaussian outside it costs the warp nothing more;
//  then steps 2-4 for each half of 16 Gaussians with a bit in the mask:
//  2. the dot products of the half's values with the pixel gradients, values [16 x D] x pixel
//     gradients^T [D x 32 pixels], which the alpha gradients need, on tensor cores
//     (tf32_mma.cuh, 3xTF32: FP32 accuracy);
//  3. the per-pixel scalar work (transmittance, alpha and geometry gradients) Gaussian by
//     Gaussian, leaving each pixel's weight in shared memory;
//  4. the value gradients, weights^T [16 x 32 pixels] x pixel gradients [32 pixels x D], on
//     tensor cores again.
// The same grouping of the forward's channel sums (image += weights x values) measured slower
// than the forward's per-pixel sums (H100, 100k Gaussians with 32 features: 1.26-1.29 ms
// against 1.11-1.15 ms): the forward stops each pixel at its transmittance floor, the product
// cannot. CH is the channel capacity (>= D), fixed at compile time: the accumulator tiles live in
// registers.
static_assert(kTileSize == 16, "a warp is two rows of a 16-pixel-wide tile");
constexpr int kWarps = kBlock / 32;
constexpr unsigned kFullMask = 0xffffffffu;

// Tiles of 8 channels that hold CH channels (the N or K extent of the channel products).
constexpr int channelTiles(int CH) { return (CH + 7) / 8; }

// Step 1: bit l set when Gaussian j0 + l of the batch (l < in_group) reaches warp `warp`'s
// pixels (its staged bit) and `wanted` holds for lane l.
__device__ __forceinline__ unsigned groupMask(int j0, int in_group, int lane, bool wanted,
                                              const unsigned char* s_warps, int warp) {
  const bool reach = lane < in_group && wanted && ((s_warps[j0 + lane] >> warp) & 1u);
  return __ballot_sync(kFullMask, reach);
}

// Row stride of a warp's rows[Gaussian][pixel] in the backward (dot products, then weights): 36
// floats, so the A-fragment loads of the value gradients (Gaussian = group (+ 8), pixel = quad
// (+ 4)) fall in 32 different banks (4 group + quad).
constexpr int kBackwardRowStride = 36;

// Row stride of a pixel's gradient in shared memory: CH rounded up to 8 (zero padded) plus 4, so
// the dot products' B-fragment loads (pixel = group, channel = quad) fall in 32 different banks
// (12 group + quad, modulo 32); the value gradients' loads meet at most 2-way conflicts.
constexpr int gradientRowStride(int CH) { return 8 * channelTiles(CH) + 4; }

// Sums six per-lane numbers over the warp and adds them to Gaussian g's gradients (mean2d x, y;
// conic a, b, c; opacity). A transposing butterfly: each of the first three exchanges halves
// the numbers a lane carries while it sums pairs (4 + 2 + 1 shuffles), so lane l then carries
// number l / 4 summed over 8 lanes; two more exchanges finish the sums, and lanes 0, 4, .., 20
// add one number each (9 shuffles and one atomic step instead of 6 x 5 and six).
__device__ __forceinline__ void addGeometryGradients(const float (&v)[6], int g, int lane,
                                                     float* g_means2d, float* g_conics,
                                                     float* g_opacities) {
  const bool b4 = lane & 16, b3 = lane & 8, b2 = lane & 4;
  float u[4];  // numbers 4 b4 + i
#pragma unroll
  for (int i = 0; i < 4; ++i) {
    const float low = v[i], high = i + 4 < 6 ? v[i + 4] : 0.f;
    u[i] = (b4 ? high : low) + __shfl_xor_sync(kFullMask, b4 ? low : high, 16);
  }
  float t[2];  // numbers 4 b4 + 2 b3 + i
#pragma unroll
  for (int i = 0; i < 2; ++i) {
    t[i] = (b3 ? u[i + 2] : u[i]) + __shfl_xor_sync(kFullMask, b3 ? u[i] : u[i + 2], 8);
  }
  float s = (b2 ? t[1] : t[0]) + __shfl_xor_sync(kFullMask, b2 ? t[0] : t[1], 4);
  s += __shfl_xor_sync(kFullMask, s, 2);
  s += __shfl_xor_sync(kFullMask, s, 1);
  const int number = lane / 4;  // 4 b4 + 2 b3 + b2
  if (lane % 4 == 0 && number < 6) {
    float* target = number < 2   ? g_means2d + 2 * g + number
                    : number < 5 ? g_conics + 3 * g + (number - 2)
                                 : g_opacities + g;
    atomicAdd(target, s);
  }
}

// rows[Gaussian][pixel] = values[ids[Gaussian]] . gradient of the pixel for the 16 Gaussians of
// a half group (a row tile of the product) in `mask` (bit r: Gaussian r of the half):
// [16 x D] x [D x 32 pixels].
template <int CH>
__device__ __forceinline__ void halfDots(unsigned mask, const int* ids,
                                         const float* __restrict__ values, int D,
                                         const float* warp_gpix, float (*rows)[kBackwardRowStride],
                                         int group, int quad) {
  constexpr int S = gradientRowStride(CH);
  const int g0 = group, g1 = g0 + 8;
  const float* v0 = (mask >> g0) & 1u ? values + static_cast<int64_t>(ids[g0]) * D : nullptr;
  const float* v1 = (mask >> g1) & 1u ? values + static_cast<int64_t>(ids[g1]) * D : nullptr;
  float acc[4][4] = {};  // pixel tiles 8 n .. 8 n + 7
#pragma unroll
  for (int k = 0; k < channelTiles(CH); ++k) {  // channels: the K extent
    if (8 * k >= D) break;
    const int c0 = 8 * k + quad, c1 = c0 + 4;
    const Tf32Split a[4] = {splitTf32(v0 && c0 < D ? __ldg(v0 + c0) : 0.f),
                            splitTf32(v1 && c0 < D ? __ldg(v1 + c0) : 0.f),
                            splitTf32(v0 && c1 < D ? __ldg(v0 + c1) : 0.f),
                            splitTf32(v1 && c1 < D ? __ldg(v1 + c1) : 0.f)};
#pragma unroll
    for (int n = 0; n < 4; ++n) {
      const float* gp = warp_gpix + (8 * n + group) * S;  // B: channel rows, pixel columns
      const Tf32Split b[2] = {splitTf32(gp[c0]), splitTf32(gp[c1])};
      mma3xTf32(acc[n], a, b);
    }
  }
#pragma unroll
  for (int n = 0; n < 4; ++n) {
    const int p = 8 * n + 2 * quad;
    *reinterpret_cast<float2*>(&rows[g0][p]) = make_float2(acc[n][0], acc[n][1]);
    *reinterpret_cast<float2*>(&rows[g1][p]) = make_float2(acc[n][2], acc[n][3]);
  }
}

// g_values[ids[Gaussian]] += sum over the warp's pixels p of rows[Gaussian][p] (the weights) x the
// gradient of p for the first `in_half` Gaussians of a half group: [16 x 32 pixels] x [32 x D].
// One atomic per Gaussian, channel and warp, none for a zero sum (a Gaussian that reached no
// pixel of the warp).
template <int CH>
__device__ __forceinline__ void addHalfValueGradients(int in_half, const int* ids, float* g_values,
                                                      int D, const float* warp_gpix,
                                                      const float (*rows)[kBackwardRowStride],
                                                      int group, int quad) {
  constexpr int S = gradientRowStride(CH);
  const int g0 = group, g1 = g0 + 8;
  const bool in0 = g0 < in_half, in1 = g1 < in_half;
  Tf32Split a[4][4];  // A: Gaussian rows, pixel columns 8 k + quad (+ 4), for every k
#pragma unroll
  for (int k = 0; k < 4; ++k) {
    const int p0 = 8 * k + quad, p1 = p0 + 4;
    a[k][0] = splitTf32(in0 ? rows[g0][p0] : 0.f);
    a[k][1] = splitTf32(in1 ? rows[g1][p0] : 0.f);
    a[k][2] = splitTf32(in0 ? rows[g0][p1] : 0.f);
    a[k][3] = splitTf32(in1 ? rows[g1][p1] : 0.f);
  }
  float* out0 = in0 ? g_values + static_cast<int64_t>(ids[g0]) * D : nullptr;
  float* out1 = in1 ? g_values + static_cast<int64_t>(ids[g1]) * D : nullptr;
#pragma unroll
  for (int n = 0; n < channelTiles(CH); ++n) {
    if (8 * n >= D) break;
    float acc[4] = {0.f, 0.f, 0.f, 0.f};
#pragma unroll
    for (int k = 0; k < 4; ++k) {
      const float* gp = warp_gpix + (8 * k + quad) * S + 8 * n + group;  // B: pixel rows
      const Tf32Split b[2] = {splitTf32(gp[0]), splitTf32(gp[4 * S])};
      mma3xTf32(acc, a[k], b);
    }
    const int c = 8 * n + 2 * quad;
    if (out0 && c < D && acc[0] != 0.f) atomicAdd(out0 + c, acc[0]);
    if (out0 && c + 1 < D && acc[1] != 0.f) atomicAdd(out0 + c + 1, acc[1]);
    if (out1 && c < D && acc[2] != 0.f) atomicAdd(out1 + c, acc[2]);
    if (out1 && c + 1 < D && acc[3] != 0.f) atomicAdd(out1 + c + 1, acc[3]);
  }
}

// Back to front over each tile's list, in the groups above. The opacity gradient needs, per
// Gaussian, the dot product of the pixel gradient with the colour accumulated behind it,
// sum_c accum[c] * dL/dpixel[c]. The pixel gradient is the same for every Gaussian of the pixel,
// so it follows the same recurrence as the colour (accum <- a * value + (1 - a) * accum) and is
// carried as one scalar instead of D accumulators. Dynamic shared memory: kWarps * 32 *
// gradientRowStride(CH) floats of pixel gradients. kClosedGates: negative opacities are closed
// gates and get their gradient (raster_backend.h); without, the kernel has no such branch (it
// cost the 36-channel backward ~2 %, H100).
template <int CH, bool kClosedGates>
__global__ void __launch_bounds__(kBlock)
    rasterizeBackwardKernel(int width, int height, int tiles_x, int D,
                            const int* __restrict__ ranges, const int* __restrict__ ids,
                           bool warps_packed,
                            const float* __restrict__ means2d, const float* __restrict__ conics,
                            const float* __restrict__ opacities, const float* __restrict__ values,
                            const float* __restrict__ alpha_fwd, const int* __restrict__ last_fwd,
                            const float* __restrict__ g_image, const float* __restrict__ g_alpha,
                            float* g_means2d, float* g_conics, float* g_opacities,
                            float* g_values) {
  constexpr int S = gradientRowStride(CH);
  const int tile = blockIdx.x;
  const int tx = tile % tiles_x, ty = tile / tiles_x;
  const int px = tx * kTileSize + threadIdx.x % kTileSize;
  const int py = ty * kTileSize + threadIdx.x / kTileSize;
  const bool inside = px < width && py < height;
  const float fx = px + 0.5f, fy = py + 0.5f;
  const int start = ranges[2 * tile], stop = ranges[2 * tile + 1];
  const int lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  const int group = lane / 4, quad = lane % 4;

  __shared__ int s_id[kBlock];
  __shared__ float s_mean[kBlock][2];
  __shared__ float s_conic[kBlock][3];
  __shared__ float s_opacity[kBlock];
  __shared__ unsigned char s_warps[kBlock];
  // [warp][Gaussian in half group][pixel]: the half's dot products, overwritten by its weights
  __shared__ __align__(16) float s_rows[kWarps][16][kBackwardRowStride];
  extern __shared__ float s_gpix[];  // [warp][pixel][S], channels >= D zero
  float(*rows)[kBackwardRowStride] = s_rows[warp];
  const float* warp_gpix = s_gpix + static_cast<int64_t>(warp) * 32 * S;

  const int64_t pix = inside ? static_cast<int64_t>(py) * width + px : 0;
  const float final_trans = inside ? 1.f - alpha_fwd[pix] : 1.f;
  const int last = inside ? last_fwd[pix] : 0;
  const float ga_out = inside && g_alpha != nullptr ? g_alpha[pix] : 0.f;
  float* my_gpix = s_gpix + (static_cast<int64_t>(warp) * 32 + lane) * S;
  if constexpr (copiesWarpRows(CH)) {
    // The gradient image's rows come in through shared memory. Channels D .. S and pixels
    // outside stay zero.
    for (int c = inside ? D : 0; c < S; ++c) my_gpix[c] = 0.f;
    float* warp_rows = s_gpix + static_cast<int64_t>(warp) * 32 * S;
    forEachWarpRowFloat<true>(
        tx, ty, warp, lane, width, height, D,
        [&](int64_t i, int, int pixel, int c) { warp_rows[pixel * S + c] = g_image[i]; });
    __syncwarp();
  } else {
    for (int c = 0; c < S; ++c) my_gpix[c] = c < D && inside ? g_image[pix * D + c] : 0.f;
  }
  float trans = final_trans;
  float last_alpha = 0.f;
  float behind = 0.f;    // sum_c (colour accumulated behind the current Gaussian)[c] * gpix[c]
  float last_dot = 0.f;  // sum_c (value of the Gaussian visited before)[c] * gpix[c]
  // List entries behind every pixel's last contributor add nothing: start at the block's
  // largest `last` instead of the list's end (at 1M Gaussians most of a tile's list lies there),
  // and a warp skips the entries behind its own pixels' largest.
  __shared__ int s_end;
  if (threadIdx.x == 0) s_end = 0;
  __syncthreads();
  if (last > 0) atomicMax(&s_end, last);
  __syncthreads();
  const int end = min(stop, start + s_end);
  int warp_last = last;
#pragma unroll
  for (int offset = 16; offset > 0; offset /= 2) {
    warp_last = max(warp_last, __shfl_xor_sync(kFullMask, warp_last, offset));
  }

  for (int batch_end = end; batch_end > start; batch_end -= kBlock) {
    __syncthreads();
    const int k = batch_end - 1 - threadIdx.x;
    if (k >= start) {
      stageGaussian(k, ids, warps_packed, means2d, conics, opacities, s_id, s_mean, s_conic,
                    s_opacity, s_warps);
    }
    __syncthreads();
    const int count = min(kBlock, batch_end - start);
    const int first_position = batch_end - 1 - start;  // list position of batch entry 0
    for (int j0 = 0; j0 < count; j0 += 32) {
      const int in_group = min(32, count - j0);
      const unsigned mask =
          groupMask(j0, in_group, lane, first_position - j0 - lane < warp_last, s_warps, warp);
      // Half by half (16 Gaussians, one row tile of the products): the products' rows then take
      // half the shared memory, which lets three blocks share an SM at 36 channels instead of two.
#pragma unroll
      for (int h = 0; h < 2; ++h) {
        const int h0 = 16 * h, in_half = min(16, in_group - h0);
        const unsigned half_mask = (mask >> h0) & 0xffffu;
        if (in_half <= 0) break;
        if (half_mask == 0) continue;
        halfDots<CH>(half_mask, s_id + j0 + h0, values, D, warp_gpix, rows, group, quad);
        __syncwarp();
        bool any_weight = false;
        for (int r = 0; r < in_half; ++r) {
          float w = 0.f;
          if ((half_mask >> r) & 1u) {
            const int j = j0 + h0 + r;
            float G = 0.f, alpha = 0.f;
            bool clamped = false;
            if (first_position - j < last) {
              alpha = pixelAlpha(s_mean[j], s_conic[j], s_opacity[j], fx, fy, &G, &clamped);
            }
            const bool contributes = alpha > 0.f;
            const bool closed =
                kClosedGates && !contributes && closedGateReaches(s_opacity[j], G);
            if (__any_sync(kFullMask, contributes || closed)) {
              float grads[6] = {0.f, 0.f, 0.f, 0.f, 0.f, 0.f};  // mean2d, conic, opacity
              if (closed) {  // raster_cpu_tiles.h, unblendClosedGate
                const float dot = rows[r][lane];
                behind = last_alpha * last_dot + (1.f - last_alpha) * behind;
                const float g_a = (dot - behind) * trans + ga_out * final_trans;
                last_dot = dot;
                last_alpha = 0.f;
                grads[5] = G * g_a;
              }
              if (contributes) {
                const float inv_keep = 1.f / (1.f - alpha);  // one division, used twice
                trans *= inv_keep;
                w = alpha * trans;
                const float dot = rows[r][lane];
                behind = last_alpha * last_dot + (1.f - last_alpha) * behind;
                const float g_a = (dot - behind) * trans + ga_out * final_trans * inv_keep;
                last_dot = dot;
                last_alpha = alpha;
                pixelAlphaBackward(s_mean[j], s_conic[j], s_opacity[j], fx, fy, G, clamped, g_a,
                                   grads, grads + 2, grads + 5);
              }
              addGeometryGradients(grads, s_id[j], lane, g_means2d, g_conics, g_opacities);
            }
          }
          rows[r][lane] = w;
          any_weight = any_weight || w != 0.f;
        }
        __syncwarp();
        if (__any_sync(kFullMask, any_weight)) {
          addHalfValueGradients<CH>(in_half, s_id + j0 + h0, g_values, D, warp_gpix, rows, group,
                                    quad);
        }
        __syncwarp();
      }
    }
  }
}

// The smallest compiled channel capacity that holds D channels.
int channelCapacity(int64_t D) {
  for (int capacity : {4, 8, 16, 36, 68, 132}) {
    if (D <= capacity) return capacity;
  }
  throw Error("<render>", "channels", "at most 132 (RGB + 128 features + depth)",
              std::to_string(D));
}

#define SADSPLAT_FOR_CHANNEL_CAPACITY(D, LAUNCH) \
  switch (channelCapacity(D)) {                  \
    case 4:                                      \
      LAUNCH(4);                                 \
      break;                                     \
    case 8:                                      \
      LAUNCH(8);                                 \
      break;                                     \
    case 16:                                     \
      LAUNCH(16);                                \
      break;                                     \
    case 36:                                     \
      LAUNCH(36);                                \
      break;                                     \
    case 68:                                     \
      LAUNCH(68);                                \
      break;                                     \
    default:                                     \
      LAUNCH(132);                               \
      break;                                     \
  }

// Launches a backward kernel with `smem` bytes of dynamic shared memory (raising the kernel's
// limit above the 48 KiB default where needed).
template <typename Kernel, typename... Args>
void launchBackward(Kernel kernel, int blocks, std::size_t smem, cudaStream_t stream,
                    Args... args) {
  // Static shared memory plus `smem` exceeds the 48 KiB default: opt in to more.
  cudaFuncSetAttribute(kernel, cudaFuncAttributeMaxDynamicSharedMemorySize, static_cast<int>(smem));
  kernel<<<blocks, kBlock, smem, stream>>>(args...);
}

}  // namespace

ProjectionResult projectForwardCuda(const at::Tensor& means, const at::Tensor& quats,
                                    const at::Tensor& log_scales, const CameraParams& cam,
                                    void* stream_ptr) {
  check(means, "means");
  check(quats, "quats");
  check(log_scales, "log_scales");
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t n = means.size(0);
  ProjectionResult out;
  // The kernel writes every row, also those of culled Gaussians: no fills.
  out.means2d = at::empty({n, 2}, means.options());
  out.conics = at::empty({n, 3}, means.options());
  out.depths = at::empty({n}, means.options());
  out.radii = at::empty({n}, means.options().dtype(at::kInt));
  if (n == 0) return out;
  projectForwardKernel<<<blocksFor(n), kThreads1d, 0, stream>>>(
      n, means.data_ptr<float>(), quats.data_ptr<float>(), log_scales.data_ptr<float>(),
      toCamera<float>(cam), out.means2d.data_ptr<float>(), out.conics.data_ptr<float>(),
      out.depths.data_ptr<float>(), out.radii.data_ptr<int>());
  checkLaunch("projectForwardKernel");
  return out;
}

ProjectionGrads projectBackwardCuda(const at::Tensor& means, const at::Tensor& quats,
                                    const at::Tensor& log_scales, const at::Tensor& radii,
                                    const CameraParams& cam, const at::Tensor& g_means2d,
                                    const at::Tensor& g_conics, const at::Tensor& g_depths,
                                    void* stream_ptr) {
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t n = means.size(0);
  ProjectionGrads g;
  // The kernel writes every row: no fills.
  g.means = at::empty_like(means);
  g.quats = at::empty_like(quats);
  g.log_scales = at::empty_like(log_scales);
  if (n == 0) return g;
  check(g_means2d, "grad means2d");
  check(g_conics, "grad conics");
  if (g_depths.defined()) check(g_depths, "grad depths");
  projectBackwardKernel<<<blocksFor(n), kThreads1d, 0, stream>>>(
      n, means.data_ptr<float>(), quats.data_ptr<float>(), log_scales.data_ptr<float>(),
      radii.data_ptr<int>(), toCamera<float>(cam), g_means2d.data_ptr<float>(),
      g_conics.data_ptr<float>(), g_depths.defined() ? g_depths.data_ptr<float>() : nullptr,
      g.means.data_ptr<float>(), g.quats.data_ptr<float>(), g.log_scales.data_ptr<float>());
  checkLaunch("projectBackwardKernel");
  return g;
}

at::Tensor shForwardCuda(const ShParts& sh, const at::Tensor& means,
                         const std::array<double, 3>& campos, int degree, void* stream_ptr) {
  checkShPart(sh.dc, "sh");
  checkShPart(sh.rest, "sh");
  check(means, "means");
  const int64_t n = means.size(0);
  at::Tensor colors = at::empty({n, 3}, means.options());
  if (n == 0) return colors;
  const float3 cam = make_float3(float(campos[0]), float(campos[1]), float(campos[2]));
  shForwardKernel<<<shBlocksFor(n), kShBlock, 0, static_cast<cudaStream_t>(stream_ptr)>>>(
      n, shCoefficientsForDegree(degree), degree, cam, shRows(sh), means.data_ptr<float>(),
      colors.data_ptr<float>());
  checkLaunch("shForwardKernel");
  return colors;
}

ShGrads shBackwardCuda(const ShParts& sh, const at::Tensor& means,
                       const std::array<double, 3>& campos, int degree, const at::Tensor& g_colors,
                       void* stream_ptr) {
  checkShPart(sh.dc, "sh");
  checkShPart(sh.rest, "sh");
  check(g_colors, "grad colors");
  const int64_t n = means.size(0), rest_coefficients = sh.rest.size(1);
  const int used = shCoefficientsForDegree(degree);
  ShGrads g;
  g.dc = at::empty({n, 1, 3}, means.options());
  // Coefficients above the degree get no gradient: cleared here, the kernel writes the others.
  g.rest = used - 1 < rest_coefficients ? at::zeros({n, rest_coefficients, 3}, means.options())
                                        : at::empty({n, rest_coefficients, 3}, means.options());
  g.means = at::zeros_like(means);
  if (n == 0) return g;
  const float3 cam = make_float3(float(campos[0]), float(campos[1]), float(campos[2]));
  shBackwardKernel<<<shBlocksFor(n), kShBlock, 0, static_cast<cudaStream_t>(stream_ptr)>>>(
      n, used, degree, cam, shRows(sh), means.data_ptr<float>(), g_colors.data_ptr<float>(),
      g.dc.data_ptr<float>(), g.rest.data_ptr<float>(), 3 * rest_coefficients,
      g.means.data_ptr<float>());
  checkLaunch("shBackwardKernel");
  return g;
}

RasterResult rasterizeForwardCuda(const at::Tensor& means2d, const at::Tensor& conics,
                                  const at::Tensor& opacities, const at::Tensor& values,
                                  const at::Tensor& radii, const at::Tensor& depths, int width,
                                  int height, TileListCapacity* capacity, void* stream_ptr) {
  check(means2d, "means2d");
  check(conics, "conics");
  check(opacities, "opacities");
  check(values, "values");
  check(depths, "depths");
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t D = values.size(1);
  RasterResult out;
  // Every pixel is written by the kernel (the tiles cover the image): no fill needed.
  out.image = at::empty({height, width, D}, values.options());
  out.alpha = at::empty({height, width}, values.options());
  out.last = at::empty({height, width}, values.options().dtype(at::kInt));
  out.binning =
      binGaussians(means2d, conics, radii, opacities, depths, width, height, capacity, stream);
  const int tiles_x = tileGrid(width, height).first;
  const int num_tiles = static_cast<int>(out.binning.tile_ranges.size(0));
#define SADSPLAT_LAUNCH_FORWARD(CH)                                                         \
  rasterizeForwardKernel<CH><<<num_tiles, kBlock, 0, stream>>>(                             \
      width, height, tiles_x, static_cast<int>(D), out.binning.tile_ranges.data_ptr<int>(), \
      out.binning.gaussian_ids.data_ptr<int>(), out.binning.warps_packed,                      \
      means2d.data_ptr<float>(),                                                            \
      conics.data_ptr<float>(), opacities.data_ptr<float>(), values.data_ptr<float>(),      \
      out.image.data_ptr<float>(), out.alpha.data_ptr<float>(), out.last.data_ptr<int>())
  SADSPLAT_FOR_CHANNEL_CAPACITY(D, SADSPLAT_LAUNCH_FORWARD)
#undef SADSPLAT_LAUNCH_FORWARD
  checkLaunch("rasterizeForwardKernel");
  return out;
}

RasterGrads rasterizeBackwardCuda(const at::Tensor& means2d, const at::Tensor& conics,
                                  const at::Tensor& opacities, const at::Tensor& values,
                                  const RasterResult& fwd, const at::Tensor& g_image,
                                  const at::Tensor& g_alpha, void* stream_ptr) {
  check(g_image, "grad image");
  if (g_alpha.defined()) check(g_alpha, "grad alpha");
  cudaStream_t stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t D = values.size(1);
  const int height = static_cast<int>(fwd.alpha.size(0));
  const int width = static_cast<int>(fwd.alpha.size(1));
  // The kernel adds into the four gradients: one allocation cleared at once, contiguous parts of
  // it (as_strided: one operator call each, where narrow and view take four).
  const int64_t n = means2d.size(0);
  const at::Tensor zeros = at::empty({n * (2 + 3 + 1 + D)}, values.options());
  cudaMemsetAsync(zeros.data_ptr<float>(), 0, zeros.numel() * sizeof(float), stream);
  checkLaunch("cudaMemsetAsync of the gradients");
  RasterGrads g;
  g.means2d = zeros.as_strided({n, 2}, {2, 1}, 0);
  g.conics = zeros.as_strided({n, 3}, {3, 1}, 2 * n);
  g.opacities = zeros.as_strided(opacities.sizes(), {1}, 5 * n);
  g.values = zeros.as_strided({n, D}, {D, 1}, 6 * n);
  const float* g_alpha_ptr = g_alpha.defined() ? g_alpha.data_ptr<float>() : nullptr;
  const int tiles_x = tileGrid(width, height).first;
  const int num_tiles = static_cast<int>(fwd.binning.tile_ranges.size(0));
#define SADSPLAT_LAUNCH_BACKWARD_GATES(CH, GATES)                                                  \
  launchBackward(rasterizeBackwardKernel<CH, GATES>, num_tiles,                                    \
                 sizeof(float) * kBlock * gradientRowStride(CH), stream, width, height, tiles_x,   \
                 static_cast<int>(D), fwd.binning.tile_ranges.data_ptr<int>(),                     \
                 fwd.binning.gaussian_ids.data_ptr<int>(), fwd.binning.warps_packed,                 \
                 means2d.data_ptr<float>(),                                                        \
                 conics.data_ptr<float>(), opacities.data_ptr<float>(), values.data_ptr<float>(),  \
                 fwd.alpha.data_ptr<float>(), fwd.last.data_ptr<int>(), g_image.data_ptr<float>(), \
                 g_alpha_ptr, g.means2d.data_ptr<float>(), g.conics.data_ptr<float>(),             \
                 g.opacities.data_ptr<float>(), g.values.data_ptr<float>())
#define SADSPLAT_LAUNCH_BACKWARD(CH)                  \
  if (fwd.closed_gates) {                             \
    SADSPLAT_LAUNCH_BACKWARD_GATES(CH, true);         \
  } else {                                            \
    SADSPLAT_LAUNCH_BACKWARD_GATES(CH, false);        \
  }
  SADSPLAT_FOR_CHANNEL_CAPACITY(D, SADSPLAT_LAUNCH_BACKWARD)
#undef SADSPLAT_LAUNCH_BACKWARD
#undef SADSPLAT_LAUNCH_BACKWARD_GATES
  checkLaunch("rasterizeBackwardKernel");
  return g;
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
