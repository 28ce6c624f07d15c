#pragma once
// The per-element arithmetic of the fused SSIM, shared by the CPU loops (ssim_cpu.cpp) and the
// CUDA kernels (ssim_cuda.cu); the definition is the reference composition's (image_metrics.cpp).

#if defined(__CUDACC__)
#define SADSPLAT_SSIM_HD __host__ __device__ __forceinline__
#else
#define SADSPLAT_SSIM_HD inline
#endif

namespace sadsplat {
namespace gaussians {
namespace ssim_fused {

/// Half-width of the 11-tap window.
constexpr int kRadius = 5;

/// SSIM at one element from its blurred statistics s = (E[a], E[b], E[a^2], E[b^2], E[ab]);
/// partials receives dS/dE[a], dS/dE[a^2] and dS/dE[ab] (what the backward blurs).
SADSPLAT_SSIM_HD float ssimFromStats(const float s[5], float partials[3]) {
  constexpr float kC1 = 0.01f * 0.01f, kC2 = 0.03f * 0.03f;
  const float mx = s[0], my = s[1];
  const float sxx = s[2] - mx * mx, syy = s[3] - my * my, sxy = s[4] - mx * my;
  const float A = 2 * mx * my + kC1, B = 2 * sxy + kC2;
  const float C = mx * mx + my * my + kC1, D = sxx + syy + kC2;
  const float CD = C * D;
  const float S = (A * B) / CD;
  // S = A B / (C D) with A(mx), B(mx, E[ab]), C(mx), D(mx, E[a^2]):
  partials[0] = (2 * my * (B - A) - S * 2 * mx * (D - C)) / CD;
  partials[1] = -S / D;
  partials[2] = 2 * A / CD;
  return S;
}

/// The gradient at element a (target b) from the blurred partials q: the window is symmetric, so
/// the transposed blur is the blur, and da = q0 + 2 a q1 + b q2, times `scale` (upstream / count).
SADSPLAT_SSIM_HD float ssimGradient(const float q[3], float a, float b, float scale) {
  return scale * (q[0] + 2 * a * q[1] + b * q[2]);
}

}  // namespace ssim_fused
}  // namespace gaussians
}  // namespace sadsplat
