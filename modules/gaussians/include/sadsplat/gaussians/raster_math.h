#pragma once
/// \file raster_math.h
/// \brief The math of Gaussian splatting, written once for the CPU and the CUDA rasterizer:
/// quaternion to rotation, EWA projection of the 3D covariance with the low-pass dilation,
/// conic and screen radius, per-pixel alpha, and the backward pass of each.
///
/// Conventions: world-to-camera (R, t) as in COLMAP; camera x right, y down, z forward; pixel
/// (i, j) has its centre at (i + 0.5, j + 0.5); the conic (a, b, c) is the inverse 2D covariance
/// [[a, b], [b, c]] and a Gaussian's power at offset d = mean2d - pixel is
/// -0.5 (a dx^2 + c dy^2) - b dx dy.
/// Functions are templated on the scalar so the CPU reference can run in double for gradient
/// checks; the CUDA backend uses float.

#include <cmath>
#include <cstdint>
#include <cstring>
#include <limits>
#include <type_traits>

#include "sadsplat/common/sh_degree.h"

#if defined(__CUDACC__)
#define SADSPLAT_HD __host__ __device__ __forceinline__
#else
#define SADSPLAT_HD inline
#endif

namespace sadsplat {
namespace gaussians {
namespace raster {

/// Tile edge in pixels (16 x 16 tiles, as in the reference rasterizer).
constexpr int kTileSize = 16;
/// Added to the 2D covariance's diagonal: the low-pass filter of EWA splatting (in pixels^2).
constexpr double kDilation = 0.3;
/// Contributions below this alpha are skipped.
constexpr double kMinAlpha = 1.0 / 255.0;
/// Per-Gaussian alpha is clamped to this (keeps 1 - alpha invertible in the backward pass).
constexpr double kMaxAlpha = 0.99;
/// A pixel stops once its transmittance would fall below this.
constexpr double kMinTransmittance = 1e-4;
/// The frustum clamp of the projection Jacobian: 1.3 x the half field of view.
constexpr double kFrustumClamp = 1.3;

template <typename T>
SADSPLAT_HD T mexp(T x) {
#if defined(__CUDA_ARCH__)
  return exp(x);
#else
  return std::exp(x);
#endif
}

/// exp(x) in float for the CPU rasterizer: Cephes' expf (x clamped to [-87, 88], round(x / ln 2)
/// split off, a degree-5 polynomial for the rest), written out operation by operation so that the
/// vectorised tile loops (raster_cpu_lanes_impl.h) compute the same float operations in the same
/// order on 16 pixels at once: a pixel's alpha is then the same bits in every CPU loop. Within
/// 2 ulp of std::exp on [-87, 88] (test_raster_cpu_paths.cpp); a NaN gives a NaN.
inline float expPoly(float x) {
  x = x < -87.f ? -87.f : x;
  x = x > 88.f ? 88.f : x;
  const float k = (x * 1.44269504088896341f + 12582912.f) - 12582912.f;  // round(x / ln 2)
  const float r = (x - k * 0.693359375f) - k * -2.12194440e-4f;
  const float z = r * r;
  float p = 1.9875691500e-4f;
  p = p * r + 1.3981999507e-3f;
  p = p * r + 8.3334519073e-3f;
  p = p * r + 4.1665795894e-2f;
  p = p * r + 1.6666665459e-1f;
  p = p * r + 5.0000001201e-1f;
  const float y = (p * z + r) + 1.f;
  const int32_t bits = ((k == k ? static_cast<int32_t>(k) : 0) + 127) * (1 << 23);
  float scale;
  std::memcpy(&scale, &bits, sizeof scale);
  return y * scale;
}

/// exp of a pixel's Gaussian power (pixelAlpha): expPoly for float on the CPU, the library's exp
/// otherwise (double for gradient checks). In CUDA float, the hardware's exp2 (__expf: one
/// multiply and one MUFU.EX2, as gsplat's -use_fast_math build gets it) instead of expf's
/// ~8-instruction sequence: the power lies in [-5.6, 0] wherever the alpha can reach 1/255, where
/// __expf is within 2 + 1.16 |x| ulp (CUDA Programming Guide, intrinsic functions), ~8e-7 relative.
template <typename T>
SADSPLAT_HD T alphaExp(T x) {
#if defined(__CUDA_ARCH__)
  if constexpr (std::is_same_v<T, float>) {
    return __expf(x);
  } else {
    return exp(x);
  }
#else
  if constexpr (std::is_same_v<T, float>) {
    return expPoly(x);
  } else {
    return std::exp(x);
  }
#endif
}

template <typename T>
SADSPLAT_HD T msqrt(T x) {
#if defined(__CUDA_ARCH__)
  return sqrt(x);
#else
  return std::sqrt(x);
#endif
}

template <typename T>
SADSPLAT_HD T mlog(T x) {
#if defined(__CUDA_ARCH__)
  return log(x);
#else
  return std::log(x);
#endif
}

template <typename T>
SADSPLAT_HD T mceil(T x) {
#if defined(__CUDA_ARCH__)
  return ceil(x);
#else
  return std::ceil(x);
#endif
}

template <typename T>
SADSPLAT_HD T floorOf(T x) {
#if defined(__CUDA_ARCH__)
  return floor(x);
#else
  return std::floor(x);
#endif
}

template <typename T>
SADSPLAT_HD bool mfinite(T x) {
#if defined(__CUDA_ARCH__)
  return isfinite(x);
#else
  return std::isfinite(x);
#endif
}

template <typename T>
SADSPLAT_HD T mmin(T a, T b) {
  return a < b ? a : b;
}
template <typename T>
SADSPLAT_HD T mmax(T a, T b) {
  return a > b ? a : b;
}

/// A pinhole (or orthographic) camera with its world-to-camera pose, in the scalar type of the
/// computation. Pinhole: pixel = f p_xy / p_z + c. Orthographic: pixel = f p_xy + c (f in pixels
/// per world unit); the projection is affine, so its Jacobian is the constant diag(fx, fy) and the
/// 2D covariance J R S R^T J^T is exact (no frustum clamp, no first-order approximation).
template <typename T>
struct Camera {
  T R[9];  ///< row-major world-to-camera rotation
  T t[3];  ///< world-to-camera translation
  T fx, fy, cx, cy;
  int width, height;
  T near_plane;
  bool orthographic;
};

/// Rotation matrix (row-major) of the normalised quaternion q = (w, x, y, z).
template <typename T>
SADSPLAT_HD void quatToRotation(const T q[4], T R[9]) {
  const T n = msqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const T w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  R[0] = T(1) - T(2) * (y * y + z * z);
  R[1] = T(2) * (x * y - w * z);
  R[2] = T(2) * (x * z + w * y);
  R[3] = T(2) * (x * y + w * z);
  R[4] = T(1) - T(2) * (x * x + z * z);
  R[5] = T(2) * (y * z - w * x);
  R[6] = T(2) * (x * z - w * y);
  R[7] = T(2) * (y * z + w * x);
  R[8] = T(1) - T(2) * (x * x + y * y);
}

/// Gradient of a loss with respect to the raw quaternion, given its gradient G with respect to
/// quatToRotation(q) (row-major).
template <typename T>
SADSPLAT_HD void quatToRotationBackward(const T q[4], const T G[9], T dq[4]) {
  const T n = msqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  const T w = q[0] / n, x = q[1] / n, y = q[2] / n, z = q[3] / n;
  T g[4];
  g[0] = T(2) * (-z * G[1] + y * G[2] + z * G[3] - x * G[5] - y * G[6] + x * G[7]);
  g[1] = T(2) * (y * G[1] + z * G[2] + y * G[3] - T(2) * x * G[4] - w * G[5] + z * G[6] + w * G[7] -
                 T(2) * x * G[8]);
  g[2] = T(2) * (-T(2) * y * G[0] + x * G[1] + w * G[2] + x * G[3] + z * G[5] - w * G[6] +
                 z * G[7] - T(2) * y * G[8]);
  g[3] = T(2) * (-T(2) * z * G[0] - w * G[1] + x * G[2] + w * G[3] - T(2) * z * G[4] + y * G[5] +
                 x * G[6] + y * G[7]);
  // Through the normalisation qn = q / |q|.
  const T dot = w * g[0] + x * g[1] + y * g[2] + z * g[3];
  dq[0] = (g[0] - w * dot) / n;
  dq[1] = (g[1] - x * dot) / n;
  dq[2] = (g[2] - y * dot) / n;
  dq[3] = (g[3] - z * dot) / n;
}

/// Everything the forward projection computes for one Gaussian.
template <typename T>
struct Projected {
  T mean2d[2];  ///< pixel coordinates of the centre
  T conic[3];   ///< inverse 2D covariance (a, b, c)
  T depth;      ///< camera-space z
  int radius;   ///< 3-sigma screen radius in pixels; 0 = culled
};

/// The intermediate terms of the EWA projection of one Gaussian, shared by the forward pass and
/// the backward pass (which recomputes them instead of storing them).
template <typename T>
struct EwaTerms {
  T p[3];                     ///< centre in camera coordinates
  T Rq[9], s[3], M[9], S[9];  ///< rotation, scales, M = Rq diag(s), 3D covariance S = M M^T
  T cx_ratio, cy_ratio;       ///< x/z, y/z clamped to the frustum limits
  bool clamp_x, clamp_y;      ///< whether the clamp was active
  T tx, ty;                   ///< clamped x, y
  T J00, J02, J11, J12;       ///< the projection Jacobian's non-zero entries
  T Tm[6];                    ///< J R (2 x 3)
  T a, b, c;                  ///< 2D covariance (with the dilation)
};

template <typename T>
SADSPLAT_HD void ewaTerms(const T mean[3], const T quat[4], const T log_scale[3],
                          const Camera<T>& cam, EwaTerms<T>* e) {
  const T* R = cam.R;
  for (int i = 0; i < 3; ++i) {
    e->p[i] = R[3 * i] * mean[0] + R[3 * i + 1] * mean[1] + R[3 * i + 2] * mean[2] + cam.t[i];
  }
  quatToRotation(quat, e->Rq);
  for (int j = 0; j < 3; ++j) e->s[j] = mexp(log_scale[j]);
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) e->M[3 * i + j] = e->Rq[3 * i + j] * e->s[j];
  }
  const T* M = e->M;
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      e->S[3 * i + j] =
          M[3 * i] * M[3 * j] + M[3 * i + 1] * M[3 * j + 1] + M[3 * i + 2] * M[3 * j + 2];
    }
  }
  const T z = e->p[2];
  if (cam.orthographic) {
    e->clamp_x = e->clamp_y = false;
    e->cx_ratio = e->cy_ratio = T(0);
    e->tx = e->p[0];
    e->ty = e->p[1];
    e->J00 = cam.fx;
    e->J02 = T(0);
    e->J11 = cam.fy;
    e->J12 = T(0);
  } else {
    const T lim_x_pos = T(kFrustumClamp) * (T(cam.width) - cam.cx) / cam.fx;
    const T lim_x_neg = T(kFrustumClamp) * cam.cx / cam.fx;
    const T lim_y_pos = T(kFrustumClamp) * (T(cam.height) - cam.cy) / cam.fy;
    const T lim_y_neg = T(kFrustumClamp) * cam.cy / cam.fy;
    const T rx = e->p[0] / z, ry = e->p[1] / z;
    e->clamp_x = rx > lim_x_pos || rx < -lim_x_neg;
    e->clamp_y = ry > lim_y_pos || ry < -lim_y_neg;
    e->cx_ratio = mmin(lim_x_pos, mmax(-lim_x_neg, rx));
    e->cy_ratio = mmin(lim_y_pos, mmax(-lim_y_neg, ry));
    e->tx = e->cx_ratio * z;
    e->ty = e->cy_ratio * z;
    e->J00 = cam.fx / z;
    e->J02 = -cam.fx * e->tx / (z * z);
    e->J11 = cam.fy / z;
    e->J12 = -cam.fy * e->ty / (z * z);
  }
  for (int j = 0; j < 3; ++j) {
    e->Tm[j] = e->J00 * R[j] + e->J02 * R[6 + j];
    e->Tm[3 + j] = e->J11 * R[3 + j] + e->J12 * R[6 + j];
  }
  const T* Tm = e->Tm;
  const T* S = e->S;
  T TS[6];
  for (int r = 0; r < 2; ++r) {
    for (int j = 0; j < 3; ++j) {
      TS[3 * r + j] = Tm[3 * r] * S[j] + Tm[3 * r + 1] * S[3 + j] + Tm[3 * r + 2] * S[6 + j];
    }
  }
  e->a = TS[0] * Tm[0] + TS[1] * Tm[1] + TS[2] * Tm[2] + T(kDilation);
  e->b = TS[0] * Tm[3] + TS[1] * Tm[4] + TS[2] * Tm[5];
  e->c = TS[3] * Tm[3] + TS[4] * Tm[4] + TS[5] * Tm[5] + T(kDilation);
}

/// Projects one Gaussian (EWA splatting with the low-pass dilation). Returns false (radius 0)
/// when it is behind the near plane, degenerate (non-finite or non-positive 2D covariance) or
/// entirely off-screen.
template <typename T>
SADSPLAT_HD bool projectGaussian(const T mean[3], const T quat[4], const T log_scale[3],
                                 const Camera<T>& cam, Projected<T>* out) {
  out->radius = 0;
  EwaTerms<T> e;
  ewaTerms(mean, quat, log_scale, cam, &e);
  if (!(e.p[2] > cam.near_plane)) return false;
  const T det = e.a * e.c - e.b * e.b;
  if (!(det > T(0)) || !mfinite(det) || !mfinite(e.a) || !mfinite(e.c)) return false;
  out->conic[0] = e.c / det;
  out->conic[1] = -e.b / det;
  out->conic[2] = e.a / det;
  const T mid = T(0.5) * (e.a + e.c);
  const T lambda = mid + msqrt(mmax(T(0.1), mid * mid - det));
  const T radius = mceil(T(3) * msqrt(lambda));
  const T z = e.p[2];
  if (cam.orthographic) {
    out->mean2d[0] = cam.fx * e.p[0] + cam.cx;
    out->mean2d[1] = cam.fy * e.p[1] + cam.cy;
  } else {
    out->mean2d[0] = cam.fx * e.p[0] / z + cam.cx;
    out->mean2d[1] = cam.fy * e.p[1] / z + cam.cy;
  }
  out->depth = z;
  if (!mfinite(out->mean2d[0]) || !mfinite(out->mean2d[1]) || !mfinite(radius)) return false;
  // Off-screen: the 3-sigma box misses the image.
  if (out->mean2d[0] + radius <= T(0) || out->mean2d[0] - radius >= T(cam.width) ||
      out->mean2d[1] + radius <= T(0) || out->mean2d[1] - radius >= T(cam.height)) {
    return false;
  }
  out->radius = static_cast<int>(radius);
  return true;
}

/// Backward of projectGaussian for a Gaussian it kept: from the gradients of mean2d, conic and
/// depth to those of the mean, the quaternion and the log-scales (added to the outputs).
template <typename T>
SADSPLAT_HD void projectGaussianBackward(const T mean[3], const T quat[4], const T log_scale[3],
                                         const Camera<T>& cam, const T g_mean2d[2],
                                         const T g_conic[3], T g_depth, T g_mean[3], T g_quat[4],
                                         T g_log_scale[3]) {
  const T* R = cam.R;
  EwaTerms<T> e;
  ewaTerms(mean, quat, log_scale, cam, &e);
  const T* Tm = e.Tm;
  const T* S = e.S;
  const T* M = e.M;
  const T z = e.p[2];
  const T det = e.a * e.c - e.b * e.b;
  const T Y[3] = {e.c / det, -e.b / det, e.a / det};  // conic (ya, yb, yc)

  // Conic = X^-1: dL/dX = -Y Gm Y with Gm = [[ga, gb/2], [gb/2, gc]] (b is one variable).
  const T ga = g_conic[0], gb = T(0.5) * g_conic[1], gc = g_conic[2];
  const T P00 = ga * Y[0] + gb * Y[1], P01 = ga * Y[1] + gb * Y[2];
  const T P10 = gb * Y[0] + gc * Y[1], P11 = gb * Y[1] + gc * Y[2];
  const T G01 = -(Y[0] * P01 + Y[1] * P11);
  const T G2[4] = {-(Y[0] * P00 + Y[1] * P10), G01, G01, -(Y[1] * P01 + Y[2] * P11)};

  // dL/dS = Tm^T G2 Tm (3 x 3), dL/dTm = 2 G2 Tm S (2 x 3).
  T G2T[6];  // G2 Tm
  for (int j = 0; j < 3; ++j) {
    G2T[j] = G2[0] * Tm[j] + G2[1] * Tm[3 + j];
    G2T[3 + j] = G2[2] * Tm[j] + G2[3] * Tm[3 + j];
  }
  T gS[9];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) gS[3 * i + j] = Tm[i] * G2T[j] + Tm[3 + i] * G2T[3 + j];
  }
  T gTm[6];
  for (int r = 0; r < 2; ++r) {
    for (int j = 0; j < 3; ++j) {
      gTm[3 * r + j] =
          T(2) * (G2T[3 * r] * S[j] + G2T[3 * r + 1] * S[3 + j] + G2T[3 * r + 2] * S[6 + j]);
    }
  }
  // Tm = J R: dL/dJ = gTm R^T; only J00, J02, J11, J12 are variables.
  const T gJ00 = gTm[0] * R[0] + gTm[1] * R[1] + gTm[2] * R[2];
  const T gJ02 = gTm[0] * R[6] + gTm[1] * R[7] + gTm[2] * R[8];
  const T gJ11 = gTm[3] * R[3] + gTm[4] * R[4] + gTm[5] * R[5];
  const T gJ12 = gTm[3] * R[6] + gTm[4] * R[7] + gTm[5] * R[8];
  T gp[3] = {T(0), T(0), T(0)};
  if (cam.orthographic) {
    // J is constant; mean2d = f p_xy + c; depth = z.
    gp[0] += g_mean2d[0] * cam.fx;
    gp[1] += g_mean2d[1] * cam.fy;
    gp[2] += g_depth;
  } else {
    // J as a function of (tx, ty, z); tx = clamp(x / z) z.
    const T z2 = z * z, z3 = z2 * z;
    gp[2] += -cam.fx / z2 * gJ00 + T(2) * cam.fx * e.tx / z3 * gJ02 - cam.fy / z2 * gJ11 +
             T(2) * cam.fy * e.ty / z3 * gJ12;
    const T g_tx = -cam.fx / z2 * gJ02;
    const T g_ty = -cam.fy / z2 * gJ12;
    if (e.clamp_x) {
      gp[2] += g_tx * e.cx_ratio;  // tx = lim z
    } else {
      gp[0] += g_tx;
    }
    if (e.clamp_y) {
      gp[2] += g_ty * e.cy_ratio;
    } else {
      gp[1] += g_ty;
    }
    // mean2d = f p / z + c; depth = z.
    gp[0] += g_mean2d[0] * cam.fx / z;
    gp[1] += g_mean2d[1] * cam.fy / z;
    gp[2] += -g_mean2d[0] * cam.fx * e.p[0] / z2 - g_mean2d[1] * cam.fy * e.p[1] / z2 + g_depth;
  }
  for (int j = 0; j < 3; ++j) g_mean[j] += R[j] * gp[0] + R[3 + j] * gp[1] + R[6 + j] * gp[2];

  // S = M M^T: dL/dM = 2 gS M (gS symmetric).
  T gM[9];
  for (int i = 0; i < 3; ++i) {
    for (int j = 0; j < 3; ++j) {
      gM[3 * i + j] =
          T(2) * (gS[3 * i] * M[j] + gS[3 * i + 1] * M[3 + j] + gS[3 * i + 2] * M[6 + j]);
    }
  }
  T gR[9];
  for (int j = 0; j < 3; ++j) {
    T gs = T(0);
    for (int i = 0; i < 3; ++i) {
      gs += gM[3 * i + j] * e.Rq[3 * i + j];
      gR[3 * i + j] = gM[3 * i + j] * e.s[j];
    }
    g_log_scale[j] += gs * e.s[j];
  }
  T dq[4];
  quatToRotationBackward(quat, gR, dq);
  for (int k = 0; k < 4; ++k) g_quat[k] += dq[k];
}

/// Power of a Gaussian at offset (dx, dy) = mean2d - pixel centre.
template <typename T>
SADSPLAT_HD T gaussianPower(const T conic[3], T dx, T dy) {
  return T(-0.5) * (conic[0] * dx * dx + conic[2] * dy * dy) - conic[1] * dx * dy;
}

/// Tiles touched by a Gaussian's box of half-widths (rx, ry) (its alphaBox): [x0, x1) x [y0, y1),
/// clamped to the grid.
template <typename T>
SADSPLAT_HD void tileRect(const T mean2d[2], int rx, int ry, int tiles_x, int tiles_y, int* x0,
                          int* y0, int* x1, int* y1) {
  const T size = T(kTileSize);
  *x0 = mmax(0, static_cast<int>(floorOf((mean2d[0] - rx) / size)));
  *y0 = mmax(0, static_cast<int>(floorOf((mean2d[1] - ry) / size)));
  *x1 = mmin(tiles_x, static_cast<int>(floorOf((mean2d[0] + rx) / size)) + 1);
  *y1 = mmin(tiles_y, static_cast<int>(floorOf((mean2d[1] + ry) / size)) + 1);
}

/// The screen radius that holds every pixel where a Gaussian of this opacity reaches kMinAlpha,
/// for binning: opacity * exp(-d^2 / (2 lambda)) >= 1/255 needs d <= sqrt(2 ln(255 opacity))
/// sqrt(lambda), and `radius` (the 3-sigma radius) >= 3 sqrt(lambda); so the 3-sigma radius
/// scaled by min(1, sqrt(2 ln(255 opacity)) / 3), rounded up, and 0 when no pixel can reach
/// kMinAlpha. A pixel outside it would be skipped by pixelAlpha anyway: renders are unchanged,
/// faint Gaussians just touch fewer tiles (gsplat bounds its tiles by opacity as well).
template <typename T>
SADSPLAT_HD int alphaExtent(int radius, T opacity) {
  // 1 % margin on the opacity, against rounding at the threshold.
  const T q = opacity * T(1.01 / kMinAlpha);
  if (!(q > T(1)) || radius <= 0) return 0;
  const T k = msqrt(T(2) * mlog(q)) / T(3);
  if (!(k < T(1))) return radius;
  return static_cast<int>(mceil(k * T(radius)));
}

/// Half-widths (*sx, *sy) of the axis-aligned box around the ellipse where a Gaussian of this
/// opacity and conic can reach kMinAlpha: opacity * exp(-d^T C d / 2) >= 1/255 (C the conic) needs
/// d^T C d <= 2 ln(255 opacity) = k^2, and that ellipse spans k sqrt(S_xx) across and k sqrt(S_yy)
/// down, S = C^-1 (S_xx = C_yy / det C). 1 % margin on the opacity, against rounding at the
/// threshold. Returns false when no pixel can reach kMinAlpha; *sx = *sy = +inf when the conic is
/// not positive definite (no bound).
template <typename T>
SADSPLAT_HD bool alphaEllipseHalfWidths(T opacity, const T conic[3], T* sx, T* sy) {
  const T q = opacity * T(1.01 / kMinAlpha);
  if (!(q > T(1))) return false;
  const T det = conic[0] * conic[2] - conic[1] * conic[1];
  if (!(det > T(0))) {
    *sx = *sy = std::numeric_limits<T>::infinity();
    return true;
  }
  const T k2 = T(2) * mlog(q);
  *sx = msqrt(k2 * conic[2] / det);
  *sy = msqrt(k2 * conic[0] / det);
  return true;
}

/// The binning box, half-widths (*rx, *ry): alphaExtent's square cut to alphaEllipseHalfWidths'
/// box. An elongated Gaussian's square box (3 sigma of its long axis both ways) holds many tiles
/// its ellipse never reaches; renders are unchanged (a pixel outside the box has alpha <
/// kMinAlpha, which pixelAlpha skips).
template <typename T>
SADSPLAT_HD void alphaBox(int radius, T opacity, const T conic[3], int* rx, int* ry) {
  const int extent = alphaExtent(radius, opacity);
  *rx = *ry = extent;
  if (extent <= 0) return;
  T sx, sy;
  if (!alphaEllipseHalfWidths(opacity, conic, &sx, &sy)) return;
  if (sx < T(extent)) *rx = static_cast<int>(mceil(sx));
  if (sy < T(extent)) *ry = static_cast<int>(mceil(sy));
}

/// The ellipse where a Gaussian can reach kMinAlpha, d^T C d <= k2 (d = pixel centre - mean, C
/// its conic, k2 = 2 ln(255 opacity) with alphaEllipseHalfWidths' 1 % margin on the opacity), for
/// testing tiles against it exactly (alphaEllipseMeetsTile) instead of against its box.
template <typename T>
struct AlphaEllipse {
  T mean[2] = {T(0), T(0)};
  T a = T(0), b = T(0), c = T(0);  ///< the conic: d^T C d = a dx^2 + 2 b dx dy + c dy^2
  T det = T(0);                    ///< a c - b^2
  T k2 = T(0);                     ///< the bound on d^T C d
  bool bounded =
      false;  ///< false when the conic is not positive definite: every tile may be reached
};

/// Fills *e; false when no pixel can reach kMinAlpha (the opacity is too low).
template <typename T>
SADSPLAT_HD bool alphaEllipse(const T mean2d[2], const T conic[3], T opacity, AlphaEllipse<T>* e) {
  const T q = opacity * T(1.01 / kMinAlpha);
  if (!(q > T(1))) return false;
  e->mean[0] = mean2d[0];
  e->mean[1] = mean2d[1];
  e->a = conic[0];
  e->b = conic[1];
  e->c = conic[2];
  e->det = conic[0] * conic[2] - conic[1] * conic[1];
  e->k2 = T(2) * mlog(q);
  e->bounded = e->det > T(0) && conic[0] > T(0) && conic[2] > T(0);
  return true;
}

/// alphaBox from the Gaussian's alpha ellipse (filled by alphaEllipse, which returned true): the
/// same box bit for bit — alphaExtent's k is sqrt(k2) / 3 and alphaEllipseHalfWidths' sx, sy
/// take the same k2 and det — without taking the opacity's log again (alphaBox takes it twice).
template <typename T>
SADSPLAT_HD void alphaBox(int radius, const AlphaEllipse<T>& e, int* rx, int* ry) {
  *rx = *ry = 0;
  if (radius <= 0) return;
  const T k = msqrt(e.k2) / T(3);
  const int extent = !(k < T(1)) ? radius : static_cast<int>(mceil(k * T(radius)));
  *rx = *ry = extent;
  if (extent <= 0 || !(e.det > T(0))) return;
  const T sx = msqrt(e.k2 * e.c / e.det), sy = msqrt(e.k2 * e.a / e.det);
  if (sx < T(extent)) *rx = static_cast<int>(mceil(sx));
  if (sy < T(extent)) *ry = static_cast<int>(mceil(sy));
}

/// Whether the alpha ellipse meets the rectangle of pixel centres [x0, x1] x [y0, y1]: the least
/// d^T C d over the rectangle is <= k2. With the mean outside the rectangle the least value lies
/// on an edge; on the edge x = x_e it is c (dy - dy*)^2 + det / c dx^2 with dy* = -b dx / c
/// clamped to the edge (likewise for y edges) — two non-negative terms, so no cancellation.
/// Conservative like alphaBox: false only where pixelAlpha returns 0 at every centre of the
/// rectangle (the 1 % opacity margin is 0.02 in d^T C d, far above the float rounding of either).
template <typename T>
SADSPLAT_HD bool alphaEllipseMeetsRect(const AlphaEllipse<T>& e, T x0, T y0, T x1, T y1) {
  if (!e.bounded) return true;
  const T dx0 = x0 - e.mean[0], dx1 = x1 - e.mean[0];
  const T dy0 = y0 - e.mean[1], dy1 = y1 - e.mean[1];
  if (dx0 <= T(0) && dx1 >= T(0) && dy0 <= T(0) && dy1 >= T(0)) return true;
  T least = std::numeric_limits<T>::infinity();
  const T dxs[2] = {dx0, dx1}, dys[2] = {dy0, dy1};
  for (int k = 0; k < 2; ++k) {
    const T dx = dxs[k];  // edge x = x_k
    const T centre = -e.b * dx / e.c;
    const T off = mmin(mmax(centre, dy0), dy1) - centre;
    least = mmin(least, e.c * off * off + e.det / e.c * dx * dx);
    const T dy = dys[k];  // edge y = y_k
    const T centre_x = -e.b * dy / e.a;
    const T off_x = mmin(mmax(centre_x, dx0), dx1) - centre_x;
    least = mmin(least, e.a * off_x * off_x + e.det / e.a * dy * dy);
  }
  return least <= e.k2;
}

/// The rows the alpha ellipse reaches within the columns [x0, x1] (pixel-centre coordinates): the
/// least and greatest y of the ellipse's part inside that band, as *y0, *y1, widened by 0.01
/// pixel; false when the band misses the ellipse. The ellipse's top point is (-b sy / a, sy)
/// from its mean (sy = sqrt(k2 a / det)): clamped into the band it is where the band's part is
/// highest, and there the top is (-b dx + sqrt(c k2 - det dx^2)) / c; likewise the bottom.
/// Conservative like alphaEllipseMeetsRect (the 1 % opacity margin in k2 widens the range by far
/// more than the rounding); an unbounded ellipse reaches every row.
template <typename T>
SADSPLAT_HD bool alphaEllipseRows(const AlphaEllipse<T>& e, T x0, T x1, T* y0, T* y1) {
  if (!e.bounded) {
    *y0 = -std::numeric_limits<T>::infinity();
    *y1 = std::numeric_limits<T>::infinity();
    return true;
  }
  const T sx = msqrt(e.k2 * e.c / e.det), sy = msqrt(e.k2 * e.a / e.det);
  const T dx0 = x0 - e.mean[0], dx1 = x1 - e.mean[0];
  if (dx1 < -sx || dx0 > sx) return false;
  const T top_x = mmin(mmax(-e.b * sy / e.a, dx0), dx1);
  const T bottom_x = mmin(mmax(e.b * sy / e.a, dx0), dx1);
  const T top_r = msqrt(mmax(e.c * e.k2 - e.det * top_x * top_x, T(0)));
  const T bottom_r = msqrt(mmax(e.c * e.k2 - e.det * bottom_x * bottom_x, T(0)));
  *y1 = e.mean[1] + (-e.b * top_x + top_r) / e.c + T(0.01);
  *y0 = e.mean[1] + (-e.b * bottom_x - bottom_r) / e.c - T(0.01);
  return true;
}

/// Whether the alpha ellipse meets tile (tx, ty) (its pixel centres; columns and rows past the
/// image's edge included, which only makes the test looser).
template <typename T>
SADSPLAT_HD bool alphaEllipseMeetsTile(const AlphaEllipse<T>& e, int tx, int ty) {
  const T x0 = T(tx * kTileSize) + T(0.5), y0 = T(ty * kTileSize) + T(0.5);
  return alphaEllipseMeetsRect(e, x0, y0, x0 + T(kTileSize - 1), y0 + T(kTileSize - 1));
}

/// Alpha of a Gaussian at a pixel centre (px, py), or 0 when it is skipped (power > 0 or alpha
/// below kMinAlpha). *G receives exp(power); *clamped whether alpha hit kMaxAlpha.
template <typename T>
SADSPLAT_HD T pixelAlpha(const T mean2d[2], const T conic[3], T opacity, T px, T py, T* G,
                         bool* clamped) {
  const T power = gaussianPower(conic, mean2d[0] - px, mean2d[1] - py);
  if (power > T(0)) return T(0);
  *G = alphaExp(power);
  const T raw = opacity * *G;
  *clamped = raw > T(kMaxAlpha);
  const T alpha = *clamped ? T(kMaxAlpha) : raw;
  return alpha < T(kMinAlpha) ? T(0) : alpha;
}

/// Whether a Gaussian with a closed gate reaches the pixel: rendered with the negative opacity
/// -o (raster_backend.h, "closed gates") it blends nothing, but with opacity o it would, o G >=
/// kMinAlpha (G = exp(power) from pixelAlpha, left 0 where pixelAlpha returned before it).
template <typename T>
SADSPLAT_HD bool closedGateReaches(T opacity, T G) {
  return opacity < T(0) && -opacity * G >= T(kMinAlpha);
}

/// Backward of pixelAlpha for a contributing Gaussian: adds the gradients of mean2d, conic and
/// opacity for a gradient g_alpha of its alpha.
template <typename T>
SADSPLAT_HD void pixelAlphaBackward(const T mean2d[2], const T conic[3], T opacity, T px, T py, T G,
                                    bool clamped, T g_alpha, T g_mean2d[2], T g_conic[3],
                                    T* g_opacity) {
  if (clamped) return;  // alpha = kMaxAlpha does not depend on the Gaussian
  *g_opacity += G * g_alpha;
  const T g_power = opacity * G * g_alpha;
  const T dx = mean2d[0] - px, dy = mean2d[1] - py;
  g_mean2d[0] += -g_power * (conic[0] * dx + conic[1] * dy);
  g_mean2d[1] += -g_power * (conic[2] * dy + conic[1] * dx);
  g_conic[0] += T(-0.5) * dx * dx * g_power;
  g_conic[1] += -dx * dy * g_power;
  g_conic[2] += T(-0.5) * dy * dy * g_power;
}

/// Real spherical-harmonics basis (degree <= 3, the constants of 3DGS) at the unit direction d;
/// writes (degree + 1)^2 values.
template <typename T>
SADSPLAT_HD void shBasis(const T d[3], int degree, T b[16]) {
  const T x = d[0], y = d[1], z = d[2];
  b[0] = T(0.28209479177387814);
  if (degree < 1) return;
  const T C1 = T(0.4886025119029199);
  b[1] = -C1 * y;
  b[2] = C1 * z;
  b[3] = -C1 * x;
  if (degree < 2) return;
  const T xx = x * x, yy = y * y, zz = z * z;
  b[4] = T(1.0925484305920792) * x * y;
  b[5] = T(-1.0925484305920792) * y * z;
  b[6] = T(0.31539156525252005) * (T(2) * zz - xx - yy);
  b[7] = T(-1.0925484305920792) * x * z;
  b[8] = T(0.5462742152960396) * (xx - yy);
  if (degree < 3) return;
  b[9] = T(-0.5900435899266435) * y * (T(3) * xx - yy);
  b[10] = T(2.890611442640554) * x * y * z;
  b[11] = T(-0.4570457994644658) * y * (T(4) * zz - xx - yy);
  b[12] = T(0.3731763325901154) * z * (T(2) * zz - T(3) * xx - T(3) * yy);
  b[13] = T(-0.4570457994644658) * x * (T(4) * zz - xx - yy);
  b[14] = T(1.445305721320277) * z * (xx - yy);
  b[15] = T(-0.5900435899266435) * x * (xx - T(3) * yy);
}

/// Adds to g_d the gradient with respect to d of sum_k g_b[k] * shBasis(d)[k].
template <typename T>
SADSPLAT_HD void shBasisBackward(const T d[3], int degree, const T g_b[16], T g_d[3]) {
  if (degree < 1) return;
  const T x = d[0], y = d[1], z = d[2];
  const T C1 = T(0.4886025119029199);
  g_d[1] += -C1 * g_b[1];
  g_d[2] += C1 * g_b[2];
  g_d[0] += -C1 * g_b[3];
  if (degree < 2) return;
  const T xx = x * x, yy = y * y, zz = z * z;
  const T a4 = T(1.0925484305920792), a5 = T(-1.0925484305920792), a6 = T(0.31539156525252005),
          a7 = T(-1.0925484305920792), a8 = T(0.5462742152960396);
  g_d[0] += g_b[4] * a4 * y - g_b[6] * T(2) * a6 * x + g_b[7] * a7 * z + g_b[8] * T(2) * a8 * x;
  g_d[1] += g_b[4] * a4 * x + g_b[5] * a5 * z - g_b[6] * T(2) * a6 * y - g_b[8] * T(2) * a8 * y;
  g_d[2] += g_b[5] * a5 * y + g_b[6] * T(4) * a6 * z + g_b[7] * a7 * x;
  if (degree < 3) return;
  const T c9 = T(-0.5900435899266435), c10 = T(2.890611442640554), c11 = T(-0.4570457994644658),
          c12 = T(0.3731763325901154), c13 = T(-0.4570457994644658), c14 = T(1.445305721320277),
          c15 = T(-0.5900435899266435);
  g_d[0] += g_b[9] * c9 * T(6) * x * y + g_b[10] * c10 * y * z + g_b[11] * c11 * T(-2) * x * y +
            g_b[12] * c12 * T(-6) * x * z + g_b[13] * c13 * (T(4) * zz - T(3) * xx - yy) +
            g_b[14] * c14 * T(2) * x * z + g_b[15] * c15 * (T(3) * xx - T(3) * yy);
  g_d[1] += g_b[9] * c9 * (T(3) * xx - T(3) * yy) + g_b[10] * c10 * x * z +
            g_b[11] * c11 * (T(4) * zz - xx - T(3) * yy) + g_b[12] * c12 * T(-6) * y * z +
            g_b[13] * c13 * T(-2) * x * y + g_b[14] * c14 * T(-2) * y * z +
            g_b[15] * c15 * T(-6) * x * y;
  g_d[2] += g_b[10] * c10 * x * y + g_b[11] * c11 * T(8) * y * z +
            g_b[12] * c12 * (T(6) * zz - T(3) * xx - T(3) * yy) + g_b[13] * c13 * T(8) * x * z +
            g_b[14] * c14 * (xx - yy);
}

/// Colour of one Gaussian (3DGS): SH of `degree` in the direction from the camera centre to the
/// mean, + 0.5, clamped at 0. `sh` holds K >= (degree+1)^2 coefficients, [k][channel].
template <typename T>
SADSPLAT_HD void shColor(const T* sh, int degree, const T mean[3], const T campos[3], T color[3]) {
  T d[3] = {mean[0] - campos[0], mean[1] - campos[1], mean[2] - campos[2]};
  const T norm = mmax(msqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), T(1e-12));
  for (int i = 0; i < 3; ++i) d[i] /= norm;
  T b[16];
  shBasis(d, degree, b);
  const int K = shCoefficientsForDegree(degree);
  for (int c = 0; c < 3; ++c) {
    T v = T(0.5);
    for (int k = 0; k < K; ++k) v += b[k] * sh[3 * k + c];
    color[c] = mmax(v, T(0));
  }
}

/// Backward of shColor: adds the gradients of sh (first (degree+1)^2 rows) and of the mean.
template <typename T>
SADSPLAT_HD void shColorBackward(const T* sh, int degree, const T mean[3], const T campos[3],
                                 const T g_color[3], T* g_sh, T g_mean[3]) {
  T d[3] = {mean[0] - campos[0], mean[1] - campos[1], mean[2] - campos[2]};
  const T norm = mmax(msqrt(d[0] * d[0] + d[1] * d[1] + d[2] * d[2]), T(1e-12));
  for (int i = 0; i < 3; ++i) d[i] /= norm;
  T b[16];
  shBasis(d, degree, b);
  const int K = shCoefficientsForDegree(degree);
  T g[3];
  for (int c = 0; c < 3; ++c) {
    T v = T(0.5);
    for (int k = 0; k < K; ++k) v += b[k] * sh[3 * k + c];
    g[c] = v > T(0) ? g_color[c] : T(0);  // the clamp at 0
  }
  T g_b[16];
  for (int k = 0; k < K; ++k) {
    g_b[k] = T(0);
    for (int c = 0; c < 3; ++c) {
      g_sh[3 * k + c] += b[k] * g[c];
      g_b[k] += sh[3 * k + c] * g[c];
    }
  }
  T g_d[3] = {T(0), T(0), T(0)};
  shBasisBackward(d, degree, g_b, g_d);
  // d = v / |v|: dL/dv = (g_d - d (d . g_d)) / |v|.
  const T dot = d[0] * g_d[0] + d[1] * g_d[1] + d[2] * g_d[2];
  for (int i = 0; i < 3; ++i) g_mean[i] += (g_d[i] - d[i] * dot) / norm;
}

}  // namespace raster
}  // namespace gaussians
}  // namespace sadsplat
