// The fused semantic loss on CUDA (see semantic_loss_backend.h). One warp per pixel, one lane
// per feature channel (and per class): a pixel's D features are one coalesced load, each logit
// a butterfly sum over the lanes, and d loss / d f is written back coalesced. The decoder lives
// in shared memory; its gradients are summed in registers per warp, then per block in shared
// memory, then once per block into global memory. Warps stride over the pixels (a grid of a few
// blocks per multiprocessor), so these block sums stay few.
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include <algorithm>

#include "sadsplat/common/error.h"
#include "semantic_loss_backend.h"

namespace sadsplat {
namespace gaussians {
namespace semantic_loss_fused {
namespace {

constexpr int kThreads = 256;
constexpr int kWarps = kThreads / 32;
constexpr float kMinNorm = 1e-8f;  // the reference's clamp_min of |l|

__device__ float warpSum(float v) {
  for (int off = 16; off > 0; off /= 2) v += __shfl_xor_sync(0xffffffffu, v, off);
  return v;
}

// One pixel's features and logits. S = channel slots per lane (channel lane + 32 s), K = class
// slots per lane (class lane + 32 k): the lane of class c holds l_c.
template <int S, int K>
struct Pixel {
  float f[S];
  float l[K];
  float norm, target;  // |l| and l_t, on every lane
};

template <int S, int K>
__device__ Pixel<S, K> loadPixel(const float* features, int64_t ld, int64_t p, int t,
                                 const float* sW, const float* sb, int D, int C, int lane) {
  Pixel<S, K> px;
#pragma unroll
  for (int s = 0; s < S; ++s) {
    const int d = lane + 32 * s;
    px.f[s] = d < D ? features[p * ld + d] : 0.0f;
  }
#pragma unroll
  for (int k = 0; k < K; ++k) px.l[k] = 0.0f;
#pragma unroll
  for (int c = 0; c < 32 * K; ++c) {
    if (c >= C) break;
    float partial = 0;
#pragma unroll
    for (int s = 0; s < S; ++s) {
      const int d = lane + 32 * s;
      if (d < D) partial += sW[c * D + d] * px.f[s];
    }
    const float sum = warpSum(partial);
    if (lane == c % 32) px.l[c / 32] = sum + sb[c];
  }
  float sq = 0;
#pragma unroll
  for (int k = 0; k < K; ++k) sq += px.l[k] * px.l[k];  // zero on lanes without a class
  px.norm = sqrtf(warpSum(sq));
  float mine = 0;
#pragma unroll
  for (int k = 0; k < K; ++k)
    if (k == t / 32) mine = px.l[k];
  px.target = __shfl_sync(0xffffffffu, mine, t % 32);
  return px;
}

// Grid-stride over warps: pixel p of warp w is w, w + number of warps, ...
struct WarpIndex {
  int lane, warp;
  int64_t first, stride;
};
__device__ WarpIndex warpIndex() {
  WarpIndex w;
  w.lane = threadIdx.x % 32;
  w.warp = threadIdx.x / 32;
  w.first = static_cast<int64_t>(blockIdx.x) * kWarps + w.warp;
  w.stride = static_cast<int64_t>(gridDim.x) * kWarps;
  return w;
}

__device__ void loadDecoder(const float* W, const float* b, int D, int C, float* sW, float* sb) {
  for (int k = threadIdx.x; k < C * D; k += blockDim.x) sW[k] = W[k];
  for (int k = threadIdx.x; k < C; k += blockDim.x) sb[k] = b[k];
}

template <int S, int K>
__global__ void lossForward(const float* features, int64_t ld, const int64_t* labels,
                            const float* W, const float* b, int64_t P, int D, int C, double* sums) {
  extern __shared__ float shared[];
  float* sW = shared;
  float* sb = shared + C * D;
  loadDecoder(W, b, D, C, sW, sb);
  __syncthreads();
  const WarpIndex w = warpIndex();
  double value = 0, count = 0;  // meaningful on lane 0
  for (int64_t p = w.first; p < P; p += w.stride) {
    const int64_t t = labels[p];  // the same on every lane: no divergence below
    // Labels >= C are a caller's error (the reference's gather rejects them); they count as unset.
    if (t < 0 || t >= C) continue;
    const Pixel<S, K> px = loadPixel<S, K>(features, ld, p, static_cast<int>(t), sW, sb, D, C, w.lane);
    value += 1.0 - static_cast<double>(px.target / fmaxf(px.norm, kMinNorm));
    count += 1;
  }
  __shared__ double block_sums[2][kWarps];
  if (w.lane == 0) {
    block_sums[0][w.warp] = value;
    block_sums[1][w.warp] = count;
  }
  __syncthreads();
  if (threadIdx.x == 0) {
    double v = 0, n = 0;
    for (int k = 0; k < kWarps; ++k) {
      v += block_sums[0][k];
      n += block_sums[1][k];
    }
    atomicAdd(&sums[0], v);
    atomicAdd(&sums[1], n);
  }
}

// d loss_p / d l_c = -(delta_ct / n - l_t l_c / n^3) for n = |l| >= 1e-8; below, the clamp is
// constant and d / d l_c = -delta_ct / 1e-8. Scaled by upstream / max(count, 1).
// grad_w, grad_b: null when the decoder needs no gradient, else zeroed [C, D] and [C].
template <int S, int K>
__global__ void lossBackward(const float* features, int64_t ld, const int64_t* labels,
                             const float* W, const float* b, int64_t P, int D, int C,
                             const double* sums,
                             const float* upstream, float* grad_features, float* grad_w,
                             float* grad_b) {
  extern __shared__ float shared[];
  float* sW = shared;
  float* sb = sW + C * D;
  float* block_gw = sb + C;  // the block's decoder gradient, [C, D] then [C]
  float* block_gb = block_gw + C * D;
  loadDecoder(W, b, D, C, sW, sb);
  for (int k = threadIdx.x; k < C * D + C; k += blockDim.x) block_gw[k] = 0;
  __syncthreads();
  const WarpIndex w = warpIndex();
  const bool decoder = grad_w != nullptr;
  const float scale = static_cast<float>(*upstream / fmax(sums[1], 1.0));
  float acc_w[S][32 * K];  // this lane's channels x all classes
  float acc_b[K];
#pragma unroll
  for (int k = 0; k < K; ++k) acc_b[k] = 0;
#pragma unroll
  for (int s = 0; s < S; ++s)
#pragma unroll
    for (int c = 0; c < 32 * K; ++c) acc_w[s][c] = 0;
  for (int64_t p = w.first; p < P; p += w.stride) {
    const int64_t t = labels[p];
    if (t < 0 || t >= C) {
#pragma unroll
      for (int s = 0; s < S; ++s) {
        const int d = w.lane + 32 * s;
        if (d < D) grad_features[p * D + d] = 0;
      }
      continue;
    }
    const Pixel<S, K> px = loadPixel<S, K>(features, ld, p, static_cast<int>(t), sW, sb, D, C, w.lane);
    const bool clamped = px.norm < kMinNorm;
    const float inv_n = 1.0f / fmaxf(px.norm, kMinNorm);
    const float k3 = clamped ? 0.0f : px.target * inv_n * inv_n * inv_n;
    float g[K];  // d loss / d l_c of this lane's classes
#pragma unroll
    for (int k = 0; k < K; ++k) {
      const int c = w.lane + 32 * k;
      g[k] = c < C ? scale * (k3 * px.l[k] - (c == t ? inv_n : 0.0f)) : 0.0f;
      acc_b[k] += g[k];
    }
    float gf[S];
#pragma unroll
    for (int s = 0; s < S; ++s) gf[s] = 0;
#pragma unroll
    for (int c = 0; c < 32 * K; ++c) {
      if (c >= C) break;
      float gc = 0;
#pragma unroll
      for (int k = 0; k < K; ++k)
        if (k == c / 32) gc = __shfl_sync(0xffffffffu, g[k], c % 32);
#pragma unroll
      for (int s = 0; s < S; ++s) {
        const int d = w.lane + 32 * s;
        if (d < D) {
          gf[s] += sW[c * D + d] * gc;
          acc_w[s][c] += gc * px.f[s];
        }
      }
    }
#pragma unroll
    for (int s = 0; s < S; ++s) {
      const int d = w.lane + 32 * s;
      if (d < D) grad_features[p * D + d] = gf[s];
    }
  }
  if (!decoder) return;
#pragma unroll
  for (int s = 0; s < S; ++s)
#pragma unroll
    for (int c = 0; c < 32 * K; ++c) {
      const int d = w.lane + 32 * s;
      if (c < C && d < D) atomicAdd(&block_gw[c * D + d], acc_w[s][c]);
    }
#pragma unroll
  for (int k = 0; k < K; ++k) {
    const int c = w.lane + 32 * k;
    if (c < C) atomicAdd(&block_gb[c], acc_b[k]);
  }
  __syncthreads();
  for (int k = threadIdx.x; k < C * D; k += blockDim.x) atomicAdd(&grad_w[k], block_gw[k]);
  for (int k = threadIdx.x; k < C; k += blockDim.x) atomicAdd(&grad_b[k], block_gb[k]);
}

void check(const char* what) {
  const cudaError_t err = cudaGetLastError();
  if (err != cudaSuccess) throw Error("<semantic loss>", what, "success", cudaGetErrorString(err));
}

// A few resident blocks per multiprocessor, fewer when there are fewer pixels.
unsigned gridFor(int64_t P) {
  int device = 0, sms = 0;
  cudaGetDevice(&device);
  cudaDeviceGetAttribute(&sms, cudaDevAttrMultiProcessorCount, device);
  const int64_t wanted = (P + kWarps - 1) / kWarps;
  return static_cast<unsigned>(std::max<int64_t>(1, std::min<int64_t>(wanted, 4 * sms)));
}

// The smallest instantiation that holds D channels and C classes.
bool small(int D, int C) { return D <= 32 && C <= 32; }
static_assert(kMaxChannels == 64 && kMaxClasses == 64, "the large instantiation is <2, 2>");

}  // namespace

at::Tensor forwardCuda(const at::Tensor& features, const at::Tensor& labels,
                       const at::Tensor& weight, const at::Tensor& bias, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t P = features.size(0);
  const int D = static_cast<int>(features.size(1)), C = static_cast<int>(weight.size(0));
  at::Tensor sums = at::zeros({2}, features.options().dtype(at::kDouble));
  if (P == 0) return sums;
  const size_t shared = sizeof(float) * (C * D + C);
  auto launch = [&](auto kernel) {
    kernel<<<gridFor(P), kThreads, shared, stream>>>(
        features.data_ptr<float>(), features.stride(0), labels.data_ptr<int64_t>(),
        weight.data_ptr<float>(),
        bias.data_ptr<float>(), P, D, C, sums.data_ptr<double>());
  };
  if (small(D, C))
    launch(lossForward<1, 1>);
  else
    launch(lossForward<2, 2>);
  check("lossForward");
  return sums;
}

std::array<at::Tensor, 3> backwardCuda(const at::Tensor& features, const at::Tensor& labels,
                                       const at::Tensor& weight, const at::Tensor& bias,
                                       const at::Tensor& sums, const at::Tensor& upstream,
                                       bool decoder, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int64_t P = features.size(0);
  const int D = static_cast<int>(features.size(1)), C = static_cast<int>(weight.size(0));
  at::Tensor grad_features = at::empty({P, D}, features.options());
  at::Tensor grad_w, grad_b;
  if (decoder) {
    grad_w = at::zeros_like(weight);
    grad_b = at::zeros_like(bias);
  }
  if (P == 0) return {grad_features, grad_w, grad_b};
  const size_t shared = sizeof(float) * 2 * (C * D + C);
  auto launch = [&](auto kernel) {
    kernel<<<gridFor(P), kThreads, shared, stream>>>(
        features.data_ptr<float>(), features.stride(0), labels.data_ptr<int64_t>(),
        weight.data_ptr<float>(),
        bias.data_ptr<float>(), P, D, C, sums.data_ptr<double>(), upstream.data_ptr<float>(),
        grad_features.data_ptr<float>(), decoder ? grad_w.data_ptr<float>() : nullptr,
        decoder ? grad_b.data_ptr<float>() : nullptr);
  };
  if (small(D, C))
    launch(lossBackward<1, 1>);
  else
    launch(lossBackward<2, 2>);
  check("lossBackward");
  return {grad_features, grad_w, grad_b};
}

}  // namespace semantic_loss_fused
}  // namespace gaussians
}  // namespace sadsplat
