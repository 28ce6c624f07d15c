// The fused SSIM on the CPU (see ssim_backend.h): the CUDA kernels' four passes as loops over
// image rows. Images are [H, W, 3] (channels interleaved): element i is channel i % 3 of pixel
// i / 3, a horizontal neighbour 3 elements away, a vertical one 3 W.
#include <ATen/Parallel.h>

#include <array>

#include "ssim_backend.h"
#include "ssim_math.h"

namespace sadsplat {
namespace gaussians {
namespace ssim_fused {
namespace {

// Rows per parallel chunk.
constexpr int64_t kRowGrain = 8;

// out[k][i] = sum_dx w(dx) in[k][i + 3 dx] for K maps (planes n apart), zero outside the image;
// in_b (K = 5): the statistics a, b, a^2, b^2, ab of a and b instead of K planes of `in`.
template <int K>
void horizontal(const float* in, const float* in_b, int H, int W, int64_t n,
                const std::array<float, 11>& w, float* out) {
  at::parallel_for(0, H, kRowGrain, [&](int64_t y0, int64_t y1) {
    for (int64_t y = y0; y < y1; ++y) {
      for (int x = 0; x < W; ++x) {
        for (int c = 0; c < 3; ++c) {
          const int64_t i = (y * W + x) * 3 + c;
          float acc[K] = {};
          for (int d = -kRadius; d <= kRadius; ++d) {
            const int xx = x + d;
            if (xx < 0 || xx >= W) continue;
            const int64_t j = i + 3 * d;
            const float wd = w[d + kRadius];
            if constexpr (K == 5) {
              const float p = in[j], q = in_b[j];
              acc[0] += wd * p;
              acc[1] += wd * q;
              acc[2] += wd * p * p;
              acc[3] += wd * q * q;
              acc[4] += wd * p * q;
            } else {
              for (int k = 0; k < K; ++k) acc[k] += wd * in[k * n + j];
            }
          }
          for (int k = 0; k < K; ++k) out[k * n + i] = acc[k];
        }
      }
    }
  });
}

// acc[k] = sum_dy w(dy) in[k][i + 3 W dy], zero outside the image.
template <int K>
void verticalAt(const float* in, int64_t y, int64_t i, int H, int W, int64_t n,
                const std::array<float, 11>& w, float* acc) {
  for (int k = 0; k < K; ++k) acc[k] = 0.f;
  for (int d = -kRadius; d <= kRadius; ++d) {
    const int64_t yy = y + d;
    if (yy < 0 || yy >= H) continue;
    const int64_t j = i + 3 * static_cast<int64_t>(W) * d;
    for (int k = 0; k < K; ++k) acc[k] += w[d + kRadius] * in[k * n + j];
  }
}

}  // namespace

std::array<at::Tensor, 2> forwardCpu(const at::Tensor& a, const at::Tensor& b) {
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  at::Tensor map = at::empty_like(a);
  at::Tensor partials = at::empty({3, H, W, 3}, a.options());
  if (n == 0) return {map, partials};
  const std::array<float, 11> w = window();
  at::Tensor blurred = at::empty({5, H, W, 3}, a.options());
  const float* bl = blurred.data_ptr<float>();
  horizontal<5>(a.data_ptr<float>(), b.data_ptr<float>(), H, W, n, w, blurred.data_ptr<float>());
  float* m = map.data_ptr<float>();
  float* p = partials.data_ptr<float>();
  at::parallel_for(0, H, kRowGrain, [&](int64_t y0, int64_t y1) {
    for (int64_t i = y0 * W * 3; i < y1 * W * 3; ++i) {
      float s[5], q[3];
      verticalAt<5>(bl, i / (3 * static_cast<int64_t>(W)), i, H, W, n, w, s);
      m[i] = ssimFromStats(s, q);
      for (int k = 0; k < 3; ++k) p[k * n + i] = q[k];
    }
  });
  return {map, partials};
}

at::Tensor backwardCpu(const at::Tensor& a, const at::Tensor& b, const at::Tensor& partials,
                       float upstream) {
  const int H = static_cast<int>(a.size(0)), W = static_cast<int>(a.size(1));
  const int64_t n = a.numel();
  at::Tensor grad = at::empty_like(a);
  if (n == 0) return grad;
  const std::array<float, 11> w = window();
  at::Tensor blurred = at::empty({3, H, W, 3}, a.options());
  horizontal<3>(partials.data_ptr<float>(), nullptr, H, W, n, w, blurred.data_ptr<float>());
  const float* bl = blurred.data_ptr<float>();
  const float* pa = a.data_ptr<float>();
  const float* pb = b.data_ptr<float>();
  float* g = grad.data_ptr<float>();
  const float scale = upstream / static_cast<float>(n);
  at::parallel_for(0, H, kRowGrain, [&](int64_t y0, int64_t y1) {
    for (int64_t i = y0 * W * 3; i < y1 * W * 3; ++i) {
      float q[3];
      verticalAt<3>(bl, i / (3 * static_cast<int64_t>(W)), i, H, W, n, w, q);
      g[i] = ssimGradient(q, pa[i], pb[i], scale);
    }
  });
  return grad;
}

}  // namespace ssim_fused
}  // namespace gaussians
}  // namespace sadsplat
