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

void check(const char* what) { checkCudaLaunch("<ssim>", what); }

Window makeWindow() {
  const std::array<float, 11> w = window();
  Window win;
  for (int k = 0; k < 11; ++k) win.w[k] = w[k];
  return win;
}

constexpr int kThreads = 256;
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

}  // namespace ssim_fused
}  // namespace gaussians
}  // namespace sadsplat
