#include "sadsplat/gaussians/image_metrics.h"

#include <cmath>

namespace sadsplat {
namespace gaussians {

at::Tensor ssim(const at::Tensor& a, const at::Tensor& b) {
  const auto opts = a.options();
  at::Tensor g = at::arange(11, opts).sub(5).pow(2).div(-2 * 1.5 * 1.5).exp();
  g = g / g.sum();
  // The 11x11 Gaussian window is separable: two 1-D passes, 11x fewer operations.
  const at::Tensor rows = g.view({1, 1, 1, 11}).expand({3, 1, 1, 11}).contiguous();
  const at::Tensor cols = g.view({1, 1, 11, 1}).expand({3, 1, 11, 1}).contiguous();
  const at::Tensor x = a.permute({2, 0, 1}).unsqueeze(0), y = b.permute({2, 0, 1}).unsqueeze(0);
  auto blur = [&](const at::Tensor& t) {
    const at::Tensor h = at::conv2d(t, rows, {}, 1, at::IntArrayRef({0, 5}), 1, 3);
    return at::conv2d(h, cols, {}, 1, at::IntArrayRef({5, 0}), 1, 3);
  };
  const at::Tensor mx = blur(x), my = blur(y);
  const at::Tensor sxx = blur(x * x) - mx * mx, syy = blur(y * y) - my * my;
  const at::Tensor sxy = blur(x * y) - mx * my;
  const double c1 = 0.01 * 0.01, c2 = 0.03 * 0.03;
  const at::Tensor map =
      ((2 * mx * my + c1) * (2 * sxy + c2)) / ((mx * mx + my * my + c1) * (sxx + syy + c2));
  return map.mean();
}

double psnr(const at::Tensor& a, const at::Tensor& b) {
  const double mse = (a - b).pow(2).mean().item<double>();
  return mse > 0 ? -10.0 * std::log10(mse) : 99.0;
}

}  // namespace gaussians
}  // namespace sadsplat
