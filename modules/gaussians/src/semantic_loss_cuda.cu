// The fused semantic loss on CUDA (see semantic_loss_backend.h).
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include <algorithm>

#include "sadsplat/common/cuda_support.h"
#include "semantic_loss_backend.h"

namespace sadsplat {
namespace gaussians {
namespace semantic_loss_fused {
namespace {

// Tiles of 32 pixels: a warp loads a tile's features with coalesced loads into shared memory
// (row stride D + 1: conflict-free when each lane then reads its own pixel's row), each lane
// computes one pixel, and in the backward pass the warp writes d loss / d f back coalesced and
// sums the decoder's gradient over the tile (lane = channel). The decoder lives in shared memory;
// its gradient is summed in registers per warp, per block in shared memory, then once per block
// into global memory. Warps stride over the tiles (a grid of a few blocks per multiprocessor), so
// these block sums stay few.
constexpr float kMinNorm = 1e-8f;  // the reference's clamp_min of |l|
constexpr int kTile = 32;
// 4 warps per block: at most 2 x 528 decoder floats + 4 x 1,568 tile floats, 29 KiB.
constexpr int kWarps = 4;

// Shared memory of a block: the decoder (W [C, D], b [C]), the block's decoder gradient (the same
// size; backward only) and per warp a feature tile [32, D + 1] and a logit-gradient tile [32, C].
struct Layout {
  int D, C;
  __host__ __device__ int decoder() const { return C * D + C; }
  __host__ __device__ int perWarp() const { return kTile * (D + 1) + kTile * C; }
  __host__ __device__ size_t bytes(bool backward) const {
    return sizeof(float) * ((backward ? 2 : 1) * decoder() + kWarps * perWarp());
  }
};

struct Tile {
  float* f;  // [32, D + 1]
  float* g;  // [32, C]
};

__device__ Tile warpTile(float* shared, const Layout& L, bool backward, int warp) {
  float* base = shared + (backward ? 2 : 1) * L.decoder() + warp * L.perWarp();
  return {base, base + kTile * (L.D + 1)};
}

// Loads pixels p0 .. p0 + 31 (those < P) into the tile; lane i then owns pixel p0 + i. Lane d
// holds channel d (D <= 32): the 32 loads go out together, then into shared memory.
__device__ void loadTile(const float* __restrict__ features, int64_t ld, int64_t p0, int64_t P,
                         int D, int lane, float* tile) {
  float v[kTile];
#pragma unroll
  for (int i = 0; i < kTile; ++i)
    v[i] = p0 + i < P && lane < D ? features[(p0 + i) * ld + lane] : 0.0f;
#pragma unroll
  for (int i = 0; i < kTile; ++i)
    if (lane < D) tile[i * (D + 1) + lane] = v[i];
  __syncwarp();
}

// Logits of the lane's pixel (row `row` of the tile) with W [C, D], b [C] in shared memory.
__device__ void logits(const float* row, const float* W, const float* b, int D, int C, float* l) {
#pragma unroll
  for (int c = 0; c < kMaxClasses; ++c) l[c] = c < C ? b[c] : 0.0f;
  for (int d = 0; d < D; ++d) {
    const float f = row[d];
#pragma unroll
    for (int c = 0; c < kMaxClasses; ++c)
      if (c < C) l[c] += W[c * D + d] * f;
  }
}

__device__ void normAndTarget(const float* l, int t, float* norm, float* target) {
  float sq = 0;
  *target = 0;
#pragma unroll
  for (int c = 0; c < kMaxClasses; ++c) {
    sq += l[c] * l[c];  // zero beyond C
    if (c == t) *target = l[c];
  }
  *norm = sqrtf(sq);
}

__device__ void loadDecoder(const float* W, const float* b, const Layout& L, float* shared) {
  for (int k = threadIdx.x; k < L.C * L.D; k += blockDim.x) shared[k] = W[k];
  for (int k = threadIdx.x; k < L.C; k += blockDim.x) shared[L.C * L.D + k] = b[k];
}

__global__ void lossForward(const float* features, int64_t ld, const int64_t* labels,
                            const float* W, const float* b, int64_t P, Layout L, double* sums) {
  extern __shared__ float shared[];
  loadDecoder(W, b, L, shared);
  __syncthreads();
  const float* sW = shared;
  const float* sb = shared + L.C * L.D;
  const int lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  const Tile tile = warpTile(shared, L, false, warp);
  const int64_t tiles = (P + kTile - 1) / kTile;
  double value = 0, count = 0;
  for (int64_t k = static_cast<int64_t>(blockIdx.x) * kWarps + warp; k < tiles;
       k += static_cast<int64_t>(gridDim.x) * kWarps) {
    const int64_t p0 = k * kTile, p = p0 + lane;
    loadTile(features, ld, p0, P, L.D, lane, tile.f);
    const int64_t t = p < P ? labels[p] : -1;
    // Labels >= C are a caller's error (the reference's gather rejects them); they count as unset.
    if (t >= 0 && t < L.C) {
      float l[kMaxClasses], norm, target;
      logits(tile.f + lane * (L.D + 1), sW, sb, L.D, L.C, l);
      normAndTarget(l, static_cast<int>(t), &norm, &target);
      value += 1.0 - static_cast<double>(target / fmaxf(norm, kMinNorm));
      count += 1;
    }
    __syncwarp();  // the tile is reloaded next
  }
  for (int off = 16; off > 0; off /= 2) {
    value += __shfl_down_sync(0xffffffffu, value, off);
    count += __shfl_down_sync(0xffffffffu, count, off);
  }
  if (lane == 0) {
    atomicAdd(&sums[0], value);
    atomicAdd(&sums[1], count);
  }
}

// d loss_p / d l_c = -(delta_ct / n - l_t l_c / n^3) for n = |l| >= 1e-8; below, the clamp is
// constant and d / d l_c = -delta_ct / 1e-8. Scaled by upstream / max(count, 1).
// grad_w, grad_b: null when the decoder needs no gradient, else zeroed [C, D] and [C].
__global__ void lossBackward(const float* features, int64_t ld, const int64_t* labels,
                             const float* W, const float* b, int64_t P, Layout L,
                             const double* sums, const float* upstream, float* grad_features,
                             float* grad_w, float* grad_b) {
  extern __shared__ float shared[];
  loadDecoder(W, b, L, shared);
  float* block_grad = shared + L.decoder();  // [C, D] then [C]
  for (int k = threadIdx.x; k < L.decoder(); k += blockDim.x) block_grad[k] = 0;
  __syncthreads();
  const float* sW = shared;
  const float* sb = shared + L.C * L.D;
  const int D = L.D, C = L.C;
  const int lane = threadIdx.x % 32, warp = threadIdx.x / 32;
  const Tile tile = warpTile(shared, L, true, warp);
  const bool decoder = grad_w != nullptr;
  const float scale = static_cast<float>(*upstream / fmax(sums[1], 1.0));
  // This lane's share of the decoder gradient: channel lane x all classes; bias of class lane.
  float acc_w[kMaxClasses], acc_b = 0;
#pragma unroll
  for (int c = 0; c < kMaxClasses; ++c) acc_w[c] = 0;
  const int64_t tiles = (P + kTile - 1) / kTile;
  for (int64_t k = static_cast<int64_t>(blockIdx.x) * kWarps + warp; k < tiles;
       k += static_cast<int64_t>(gridDim.x) * kWarps) {
    const int64_t p0 = k * kTile, p = p0 + lane;
    loadTile(features, ld, p0, P, D, lane, tile.f);
    const int64_t t = p < P ? labels[p] : -1;
    float g[kMaxClasses];
#pragma unroll
    for (int c = 0; c < kMaxClasses; ++c) g[c] = 0;
    if (t >= 0 && t < C) {
      float l[kMaxClasses], norm, target;
      logits(tile.f + lane * (D + 1), sW, sb, D, C, l);
      normAndTarget(l, static_cast<int>(t), &norm, &target);
      const float inv_n = 1.0f / fmaxf(norm, kMinNorm);
      const float k3 = norm < kMinNorm ? 0.0f : target * inv_n * inv_n * inv_n;
#pragma unroll
      for (int c = 0; c < kMaxClasses; ++c)
        if (c < C) g[c] = scale * (k3 * l[c] - (c == t ? inv_n : 0.0f));
    }
#pragma unroll
    for (int c = 0; c < kMaxClasses; ++c)
      if (c < C) tile.g[lane * C + c] = g[c];
    __syncwarp();
    if (decoder) {
      // Lane = channel: the sum over the tile's pixels of g_c f_d; lane = class for the bias.
      for (int i = 0; i < kTile; ++i) {
        const float f = lane < D ? tile.f[i * (D + 1) + lane] : 0.0f;
#pragma unroll
        for (int c = 0; c < kMaxClasses; ++c)
          if (c < C) acc_w[c] += tile.g[i * C + c] * f;
        if (lane < C) acc_b += tile.g[i * C + lane];
      }
      __syncwarp();  // the feature tile is overwritten with the gradient below
    }
    // d loss / d f_d = sum_c W_cd g_c, into the lane's own row, then written out coalesced.
    float* row = tile.f + lane * (D + 1);
    for (int d = 0; d < D; ++d) {
      float acc = 0;
#pragma unroll
      for (int c = 0; c < kMaxClasses; ++c)
        if (c < C) acc += sW[c * D + d] * g[c];
      row[d] = acc;
    }
    __syncwarp();
    for (int i = 0; i < kTile; ++i) {
      const int64_t q = p0 + i;
      if (q >= P) break;
      if (lane < D) grad_features[q * D + lane] = tile.f[i * (D + 1) + lane];
    }
    __syncwarp();
  }
  if (!decoder) return;
  if (lane < D) {
#pragma unroll
    for (int c = 0; c < kMaxClasses; ++c)
      if (c < C) atomicAdd(&block_grad[c * D + lane], acc_w[c]);
  }
  if (lane < C) atomicAdd(&block_grad[C * D + lane], acc_b);
  __syncthreads();
  for (int k = threadIdx.x; k < C * D; k += blockDim.x) atomicAdd(&grad_w[k], block_grad[k]);
  for (int k = threadIdx.x; k < C; k += blockDim.x) atomicAdd(&grad_b[k], block_grad[C * D + k]);
}

// The loss from forwardCuda's sums, as the reference divides: sum / max(count, 1), in float.
__global__ void lossValue(const double* sums, float* loss) {
  *loss = static_cast<float>(sums[0] / fmax(sums[1], 1.0));
}

void check(const char* what) { checkCudaLaunch("<semantic loss>", what); }

static_assert(kMaxChannels <= 32, "a lane holds one channel");

// A few resident blocks per multiprocessor, fewer when there are fewer tiles.
unsigned gridFor(int64_t P) {
  int device = 0, sms = 0;
  cudaGetDevice(&device);
  cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device);
  const int64_t tiles = (P + kTile - 1) / kTile;
  const int64_t wanted = (tiles + kWarps - 1) / kWarps;
  return static_cast<unsigned>(std::max<int64_t>(1, std::min<int64_t>(wanted, 8 * sms)));
}

}  // namespace

std::array<at::Tensor, 2> forwardCuda(const at::Tensor& features, const at::Tensor& labels,
                                      const at::Tensor& weight, const at::Tensor& bias,
                                      void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t P = labels.numel();
  const Layout L{static_cast<int>(features.size(2)), static_cast<int>(weight.size(0))};
  at::Tensor sums = at::empty({2}, features.options().dtype(at::kDouble));
  at::Tensor loss = at::empty({}, features.options());
  cudaMemsetAsync(sums.data_ptr<double>(), 0, 2 * sizeof(double), stream);
  check("cudaMemsetAsync of the sums");
  if (P > 0) {
    lossForward<<<gridFor(P), 32 * kWarps, L.bytes(false), stream>>>(
        features.data_ptr<float>(), features.stride(1), labels.data_ptr<int64_t>(),
        weight.data_ptr<float>(), bias.data_ptr<float>(), P, L, sums.data_ptr<double>());
    check("lossForward");
  }
  lossValue<<<1, 1, 0, stream>>>(sums.data_ptr<double>(), loss.data_ptr<float>());
  check("lossValue");
  return {sums, loss};
}

std::array<at::Tensor, 3> backwardCuda(const at::Tensor& features, const at::Tensor& labels,
                                       const at::Tensor& weight, const at::Tensor& bias,
                                       const at::Tensor& sums, const at::Tensor& upstream,
                                       bool decoder, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t P = labels.numel();
  const Layout L{static_cast<int>(features.size(2)), static_cast<int>(weight.size(0))};
  at::Tensor grad_features = at::empty(features.sizes(), features.options());
  at::Tensor grad_w, grad_b;
  if (decoder) {
    // The kernel adds into them: cleared here without ATen's zero-fill operators.
    grad_w = at::empty(weight.sizes(), weight.options());
    grad_b = at::empty(bias.sizes(), bias.options());
    cudaMemsetAsync(grad_w.data_ptr<float>(), 0, grad_w.numel() * sizeof(float), stream);
    cudaMemsetAsync(grad_b.data_ptr<float>(), 0, grad_b.numel() * sizeof(float), stream);
    check("cudaMemsetAsync of the decoder's gradients");
  }
  if (P == 0) return {grad_features, grad_w, grad_b};
  lossBackward<<<gridFor(P), 32 * kWarps, L.bytes(true), stream>>>(
      features.data_ptr<float>(), features.stride(1), labels.data_ptr<int64_t>(),
      weight.data_ptr<float>(), bias.data_ptr<float>(), P, L, sums.data_ptr<double>(),
      upstream.data_ptr<float>(), grad_features.data_ptr<float>(),
      decoder ? grad_w.data_ptr<float>() : nullptr, decoder ? grad_b.data_ptr<float>() : nullptr);
  check("lossBackward");
  return {grad_features, grad_w, grad_b};
}

}  // namespace semantic_loss_fused
}  // namespace gaussians
}  // namespace sadsplat
