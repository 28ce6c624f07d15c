#include "sadsplat/pseudo_labels/region_features.h"

#include <algorithm>
#include <cmath>
#include <limits>

#include "sadsplat/pseudo_labels/point_visibility.h"

namespace sadsplat {
namespace pseudo_labels {
namespace {

// Box mean of a single-channel image over a (2r+1)^2 window, via an integral image.
std::vector<float> boxMean(const std::vector<float>& img, int W, int H, int r) {
  std::vector<double> integral(static_cast<std::size_t>(W + 1) * (H + 1), 0.0);
  for (int y = 0; y < H; ++y) {
    double row = 0;
    for (int x = 0; x < W; ++x) {
      row += img[static_cast<std::size_t>(y) * W + x];
      integral[static_cast<std::size_t>(y + 1) * (W + 1) + x + 1] =
          integral[static_cast<std::size_t>(y) * (W + 1) + x + 1] + row;
    }
  }
  std::vector<float> out(img.size());
  for (int y = 0; y < H; ++y) {
    for (int x = 0; x < W; ++x) {
      const int x0 = std::max(0, x - r), x1 = std::min(W, x + r + 1);
      const int y0 = std::max(0, y - r), y1 = std::min(H, y + r + 1);
      const double s = integral[static_cast<std::size_t>(y1) * (W + 1) + x1] -
                       integral[static_cast<std::size_t>(y0) * (W + 1) + x1] -
                       integral[static_cast<std::size_t>(y1) * (W + 1) + x0] +
                       integral[static_cast<std::size_t>(y0) * (W + 1) + x0];
      out[static_cast<std::size_t>(y) * W + x] = static_cast<float>(s / ((x1 - x0) * (y1 - y0)));
    }
  }
  return out;
}

}  // namespace

SceneGeometry SceneGeometry::fromScene(const io::Scene& scene) {
  SceneGeometry g;
  std::array<double, 3> up{0, 0, 0};
  for (const io::View& v : scene.views) {
    const std::array<double, 9> R = v.camera.rotation();
    // Camera viewing direction in world = third row of R (R^T e_z); up is its opposite.
    for (int k = 0; k < 3; ++k) up[k] -= R[6 + k];
  }
  const double n = std::sqrt(up[0] * up[0] + up[1] * up[1] + up[2] * up[2]);
  if (n > 0) {
    for (int k = 0; k < 3; ++k) g.up[k] = up[k] / n;
  }
  if (scene.points.empty()) return g;
  std::vector<float> h(scene.points.size());
  for (std::size_t i = 0; i < h.size(); ++i) {
    const auto& p = scene.points[i].xyz;
    h[i] = static_cast<float>(p[0] * g.up[0] + p[1] * g.up[1] + p[2] * g.up[2]);
  }
  std::vector<float> sorted = h;
  std::sort(sorted.begin(), sorted.end());
  const float ground = sorted[sorted.size() / 50];
  const float top = sorted[sorted.size() * 98 / 100];
  for (float& x : h) x -= ground;
  g.height = std::move(h);
  g.median_height = sorted[sorted.size() / 2] - ground;
  g.scale = std::max(1e-6f, top - ground);
  return g;
}

std::vector<float> regionFeatures(const io::Scene& scene, const io::View& view,
                                  const Segmentation& seg, const SceneGeometry* geometry) {
  const int W = seg.width, H = seg.height, R = seg.num_regions;
  const std::size_t N = static_cast<std::size_t>(W) * H;
  std::vector<float> L(N), A(N), B(N), green(N);
  for (std::size_t i = 0; i < N; ++i) {
    const std::uint8_t* p = &view.rgb.pixels[3 * i];
    float lab[3];
    srgbToLab(p[0], p[1], p[2], lab);
    L[i] = lab[0], A[i] = lab[1], B[i] = lab[2];
    const float sum = static_cast<float>(p[0]) + p[1] + p[2] + 1.0f;
    green[i] = (2.0f * p[1] - p[0] - p[2]) / sum;
  }
  // Per-pixel texture: gradient of L (central differences), Laplacian of L.
  std::vector<float> gx(N, 0), gy(N, 0), lap(N, 0);
  for (int y = 1; y + 1 < H; ++y) {
    for (int x = 1; x + 1 < W; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * W + x;
      gx[i] = 0.5f * (L[i + 1] - L[i - 1]);
      gy[i] = 0.5f * (L[i + W] - L[i - W]);
      lap[i] = L[i + 1] + L[i - 1] + L[i + W] + L[i - W] - 4 * L[i];
    }
  }
  // Context: Lab means over a window about three region sizes wide, centred on each pixel.
  const int context_radius =
      std::max(4, static_cast<int>(std::sqrt(static_cast<double>(N) / std::max(1, R))) * 3 / 2);
  const std::vector<float> cL = boxMean(L, W, H, context_radius),
                           cA = boxMean(A, W, H, context_radius),
                           cB = boxMean(B, W, H, context_radius);

  // Accumulate moments per region.
  enum {
    kCount,
    kL,
    kA,
    kB,
    kL2,
    kA2,
    kB2,
    kGreen,
    kGrad,
    kJxx,
    kJxy,
    kJyy,
    kLap,
    kCL,
    kCA,
    kCB,
    kAcc
  };
  std::vector<double> acc(static_cast<std::size_t>(R) * kAcc, 0.0);
  for (std::size_t i = 0; i < N; ++i) {
    const int r = seg.region[i];
    if (r < 0) continue;
    double* a = &acc[static_cast<std::size_t>(r) * kAcc];
    a[kCount] += 1;
    a[kL] += L[i], a[kA] += A[i], a[kB] += B[i];
    a[kL2] += L[i] * L[i], a[kA2] += A[i] * A[i], a[kB2] += B[i] * B[i];
    a[kGreen] += green[i];
    a[kGrad] += std::sqrt(gx[i] * gx[i] + gy[i] * gy[i]);
    a[kJxx] += gx[i] * gx[i], a[kJxy] += gx[i] * gy[i], a[kJyy] += gy[i] * gy[i];
    a[kLap] += std::abs(lap[i]);
    a[kCL] += cL[i], a[kCA] += cA[i], a[kCB] += cB[i];
  }

  // Heights of the sparse points visible in this view (a coarse z-buffer keeps the nearest ones).
  std::vector<std::vector<float>> region_heights(R);
  if (geometry != nullptr && !geometry->height.empty()) {
    for (const PointHit& h : visiblePoints(scene, view)) {
      const int r = seg.region[h.pixel];
      if (r >= 0) region_heights[r].push_back(geometry->height[h.point]);
    }
  }

  std::vector<float> out(static_cast<std::size_t>(R) * kRegionFeatureDim, 0.0f);
  for (int r = 0; r < R; ++r) {
    const double* a = &acc[static_cast<std::size_t>(r) * kAcc];
    float* f = &out[static_cast<std::size_t>(r) * kRegionFeatureDim];
    const double n = std::max(1.0, a[kCount]);
    const double mL = a[kL] / n, mA = a[kA] / n, mB = a[kB] / n;
    f[0] = static_cast<float>(mL / 100.0);
    f[1] = static_cast<float>(mA / 100.0);
    f[2] = static_cast<float>(mB / 100.0);
    f[3] = static_cast<float>(std::sqrt(std::max(0.0, a[kL2] / n - mL * mL)) / 100.0);
    f[4] = static_cast<float>(std::sqrt(std::max(0.0, a[kA2] / n - mA * mA)) / 100.0);
    f[5] = static_cast<float>(std::sqrt(std::max(0.0, a[kB2] / n - mB * mB)) / 100.0);
    f[6] = static_cast<float>(std::sqrt(mA * mA + mB * mB) / 100.0);
    f[7] = static_cast<float>(a[kGreen] / n);
    f[8] = static_cast<float>(a[kGrad] / n / 100.0);
    const double jxx = a[kJxx] / n, jxy = a[kJxy] / n, jyy = a[kJyy] / n;
    const double tr = jxx + jyy, det_term = std::sqrt((jxx - jyy) * (jxx - jyy) + 4 * jxy * jxy);
    f[9] = static_cast<float>(tr > 1e-9 ? det_term / tr : 0.0);  // coherence: 1 = oriented stripes
    f[10] = static_cast<float>(std::log1p(a[kLap] / n));
    f[11] = static_cast<float>(a[kCL] / n / 100.0);
    f[12] = static_cast<float>(a[kCA] / n / 100.0);
    f[13] = static_cast<float>(a[kCB] / n / 100.0);
    f[14] = static_cast<float>((mL - a[kCL] / n) / 100.0);  // brighter or darker than around
    auto& hs = region_heights[r];
    if (!hs.empty() && geometry != nullptr) {
      std::nth_element(hs.begin(), hs.begin() + hs.size() / 2, hs.end());
      f[15] = hs[hs.size() / 2] / geometry->scale;
      f[16] = 1.0f;
    } else {
      f[15] = geometry != nullptr ? geometry->median_height / geometry->scale : 0.0f;
      f[16] = 0.0f;
    }
  }
  return out;
}

}  // namespace pseudo_labels
}  // namespace sadsplat
