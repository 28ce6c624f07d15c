// The fused SSIM on CUDA (see ssim_backend.h). Images are [H, W, 3] (channels interleaved), so
// element i is channel i % 3 of pixel i / 3; a horizontal neighbour is 3 elements away, a
// vertical one 3 W. Each pass is one thread per element: the separable 11-tap window as a
// horizontal pass into a buffer and a vertical pass that finishes the job.
#include <ATen/ATen.h>
#include <cuda_runtime.h>

#include "sadsplat/common/cuda_support.h"
#include "ssim_backend.h"
#include "ssim_math.h"

namespace sadsplat {
namespace gaussians {
namespace ssim_fused {
namespace {

constexpr int kThreads = 256;

// The 1-D window, passed to the kernels by value.
struct Window {
  float w[2 * kRadius + 1];
};

// Vertical pass of K maps of `in` at element i: sum_dy w(dy) in_k(i + 3 W dy), zero outside.
template <int K>
__device__ void vertical(int64_t i, int W, int H, int64_t n, const float* in, const Window& win,
                         float* acc) {
  const int y = static_cast<int>(i / (3 * static_cast<int64_t>(W)));
  for (int k = 0; k < K; ++k) acc[k] = 0.0f;
  for (int d = -kRadius; d <= kRadius; ++d) {
    const int yy = y + d;
    if (yy < 0 || yy >= H) continue;
    const int64_t j = i + 3 * static_cast<int64_t>(W) * d;
    const float w = win.w[d + kRadius];
    for (int k = 0; k < K; ++k) acc[k] += w * in[k * n + j];
  }
}

// Horizontal pass of a, b, a^2, b^2, ab: out[k][i] = sum_dx w(dx) v_k(i + 3 dx), zero outside.
__global__ void statsHorizontal(const float* a, const float* b, int W, int64_t n, Window win,
                                float* out) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const int x = static_cast<int>((i / 3) % W);
  float acc[5] = {0, 0, 0, 0, 0};
  for (int d = -kRadius; d <= kRadius; ++d) {
    const int xx = x + d;
    if (xx < 0 || xx >= W) continue;
    const int64_t j = i + 3 * static_cast<int64_t>(d);
    const float p = a[j], q = b[j], w = win.w[d + kRadius];
    acc[0] += w * p;
    acc[1] += w * q;
    acc[2] += w * p * p;
    acc[3] += w * q * q;
    acc[4] += w * p * q;
  }
  for (int k = 0; k < 5; ++k) out[k * n + i] = acc[k];
}

// SSIM map and its partial derivatives w.r.t. mean(a), E[a^2], E[ab] at every element.
__global__ void statsVertical(const float* blurred, int W, int H, int64_t n, Window win, float* map,
                              float* partials) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float s[5], q[3];
  vertical<5>(i, W, H, n, blurred, win, s);
  map[i] = ssimFromStats(s, q);
  for (int k = 0; k < 3; ++k) partials[k * n + i] = q[k];
}

__global__ void partialsHorizontal(const float* partials, int W, int64_t n, Window win,
                                   float* out) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  const int x = static_cast<int>((i / 3) % W);
  float acc[3] = {0, 0, 0};
  for (int d = -kRadius; d <= kRadius; ++d) {
    const int xx = x + d;
    if (xx < 0 || xx >= W) continue;
    const int64_t j = i + 3 * static_cast<int64_t>(d);
    const float w = win.w[d + kRadius];
    for (int k = 0; k < 3; ++k) acc[k] += w * partials[k * n + j];
  }
  for (int k = 0; k < 3; ++k) out[k * n + i] = acc[k];
}

// The vertical pass of the partials and the gradient (ssimGradient).
// `upstream` is the incoming gradient of the mean (a device scalar: no host synchronisation).
__global__ void gradientVertical(const float* blurred, const float* a, const float* b, int W, int H,
                                 int64_t n, Window win, const float* upstream, float* grad) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float s[3];
  vertical<3>(i, W, H, n, blurred, win, s);
  grad[i] = ssimGradient(s, a[i], b[i], *upstream / static_cast<float>(n));
}

// Tree-sums the block's two rows of per-thread values in a fixed order into sums[.][0]; called
// by every thread of the block after writing its own entries.
template <typename T>
__device__ void sumPairsOverBlock(T (&sums)[2][kThreads], int t) {
  __syncthreads();
  for (int half = kThreads / 2; half > 0; half /= 2) {
    if (t < half) {
      sums[0][t] += sums[0][t + half];
      sums[1][t] += sums[1][t + half];
    }
    __syncthreads();
  }
}

// The RGB loss's forward (rgbLossForwardCuda): statsVertical's partials, and per block the sums
// of the SSIM map and of |a - b| over its elements, reduced in a fixed order (no atomics).
__global__ void lossVertical(const float* blurred, const float* a, const float* b, int W, int H,
                             int64_t n, Window win, float* partials, float* block_sums) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  float ssim_value = 0.0f, l1 = 0.0f;
  if (i < n) {
    float s[5], q[3];
    vertical<5>(i, W, H, n, blurred, win, s);
    ssim_value = ssimFromStats(s, q);
    for (int k = 0; k < 3; ++k) partials[k * n + i] = q[k];
    l1 = fabsf(a[i] - b[i]);
  }
  __shared__ float sums[2][kThreads];
  const int t = static_cast<int>(threadIdx.x);
  sums[0][t] = ssim_value;
  sums[1][t] = l1;
  sumPairsOverBlock(sums, t);
  if (t == 0) {
    block_sums[2 * blockIdx.x] = sums[0][0];
    block_sums[2 * blockIdx.x + 1] = sums[1][0];
  }
}

// One block: the block sums in double, in a fixed order, into
// (1 - lambda) mean|a - b| + lambda (1 - mean SSIM).
__global__ void lossFinish(const float* block_sums, int blocks, int64_t n, float lambda,
                           float* loss) {
  __shared__ double sums[2][kThreads];
  const int t = static_cast<int>(threadIdx.x);
  double ssim_sum = 0.0, l1_sum = 0.0;
  for (int k = t; k < blocks; k += kThreads) {
    ssim_sum += block_sums[2 * k];
    l1_sum += block_sums[2 * k + 1];
  }
  sums[0][t] = ssim_sum;
  sums[1][t] = l1_sum;
  sumPairsOverBlock(sums, t);
  if (t == 0) {
    const double count = static_cast<double>(n);
    *loss = static_cast<float>((1.0 - lambda) * (sums[1][0] / count) +
                               lambda * (1.0 - sums[0][0] / count));
  }
}

// The RGB loss's gradient: gradientVertical's SSIM part scaled by -lambda, plus the L1 term's
// (1 - lambda) sign(a - b) / n (0 where a = b, as ATen's abs), times the upstream scalar.
__global__ void lossGradientVertical(const float* blurred, const float* a, const float* b, int W,
                                     int H, int64_t n, Window win, const float* upstream,
                                     float lambda, float* grad) {
  const int64_t i = static_cast<int64_t>(blockIdx.x) * blockDim.x + threadIdx.x;
  if (i >= n) return;
  float s[3];
  vertical<3>(i, W, H, n, blurred, win, s);
  const float per_element = *upstream / static_cast<float>(n);
  const float d = a[i] - b[i];
  const float sign = static_cast<float>((d > 0.0f) - (d < 0.0f));
  grad[i] = ssimGradient(s, a[i], b[i], -lambda * per_element) +
            (1.0f - lambda) * per_element * sign;
}

void check(const char* what) { checkCudaLaunch("<ssim>", what); }

Window makeWindow() {
  const std::array<float, 11> w = window();
  Window win;
  for (int k = 0; k < 11; ++k) win.w[k] = w[k];
  return win;
}

unsigned blocksFor(int64_t n) { return static_cast<unsigned>((n + kThreads - 1) / kThreads); }

}  // namespace

std::array<at::Tensor, 2> forwardCuda(const at::Tensor& a, const at::Tensor& b, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  at::Tensor map = at::empty_like(a);
  at::Tensor partials = at::empty({3, H, W, 3}, a.options());
  if (n == 0) return {map, partials};
  const Window win = makeWindow();
  at::Tensor blurred = at::empty({5, H, W, 3}, a.options());
  statsHorizontal<<<blocksFor(n), kThreads, 0, stream>>>(a.data_ptr<float>(), b.data_ptr<float>(),
                                                         W, n, win, blurred.data_ptr<float>());
  check("statsHorizontal");
  statsVertical<<<blocksFor(n), kThreads, 0, stream>>>(
      blurred.data_ptr<float>(), W, H, n, win, map.data_ptr<float>(), partials.data_ptr<float>());
  check("statsVertical");
  return {map, partials};
}

at::Tensor backwardCuda(const at::Tensor& a, const at::Tensor& b, const at::Tensor& partials,
                        const at::Tensor& upstream, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  at::Tensor grad = at::empty_like(a);
  if (n == 0) return grad;
  const Window win = makeWindow();
  at::Tensor blurred = at::empty({3, H, W, 3}, a.options());
  partialsHorizontal<<<blocksFor(n), kThreads, 0, stream>>>(partials.data_ptr<float>(), W, n, win,
                                                            blurred.data_ptr<float>());
  check("partialsHorizontal");
  gradientVertical<<<blocksFor(n), kThreads, 0, stream>>>(
      blurred.data_ptr<float>(), a.data_ptr<float>(), b.data_ptr<float>(), W, H, n, win,
      upstream.data_ptr<float>(), grad.data_ptr<float>());
  check("gradientVertical");
  return grad;
}

std::array<at::Tensor, 2> rgbLossForwardCuda(const at::Tensor& a, const at::Tensor& b,
                                             float lambda, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  const unsigned blocks = blocksFor(n);
  // One allocation: the blurred statistics (5 n; the backward's scratch later), the partials
  // (3 n) and the block sums (2 per block).
  at::Tensor workspace = at::empty({8 * n + 2 * static_cast<int64_t>(blocks)}, a.options());
  at::Tensor loss = at::empty({}, a.options());
  float* blurred = workspace.data_ptr<float>();
  float* partials = blurred + 5 * n;
  float* block_sums = partials + 3 * n;
  const Window win = makeWindow();
  if (n > 0) {
    statsHorizontal<<<blocks, kThreads, 0, stream>>>(a.data_ptr<float>(), b.data_ptr<float>(), W,
                                                     n, win, blurred);
    check("statsHorizontal");
    lossVertical<<<blocks, kThreads, 0, stream>>>(blurred, a.data_ptr<float>(),
                                                  b.data_ptr<float>(), W, H, n, win, partials,
                                                  block_sums);
    check("lossVertical");
  }
  lossFinish<<<1, kThreads, 0, stream>>>(block_sums, static_cast<int>(blocks), n > 0 ? n : 1,
                                         lambda, loss.data_ptr<float>());
  check("lossFinish");
  return {loss, workspace};
}

at::Tensor rgbLossBackwardCuda(const at::Tensor& a, const at::Tensor& b,
                               const at::Tensor& workspace, const at::Tensor& upstream,
                               float lambda, void* stream_ptr) {
  const auto stream = static_cast<cudaStream_t>(stream_ptr);
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  at::Tensor grad = at::empty_like(a);
  if (n == 0) return grad;
  const Window win = makeWindow();
  // The forward's blurred statistics are spent: their room holds the blurred partials.
  float* scratch = workspace.data_ptr<float>();
  const float* partials = scratch + 5 * n;
  partialsHorizontal<<<blocksFor(n), kThreads, 0, stream>>>(partials, W, n, win, scratch);
  check("partialsHorizontal");
  lossGradientVertical<<<blocksFor(n), kThreads, 0, stream>>>(
      scratch, a.data_ptr<float>(), b.data_ptr<float>(), W, H, n, win,
      upstream.data_ptr<float>(), lambda, grad.data_ptr<float>());
  check("lossGradientVertical");
  return grad;
}

}  // namespace ssim_fused
}  // namespace gaussians
}  // namespace sadsplat
