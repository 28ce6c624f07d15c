// The rasterizer's autograd functions and the render() pipeline. The heavy lifting is in the
// backends (raster_cpu.cpp, raster_cuda.cu); this file validates, dispatches and wires autograd.
#include "sadsplat/gaussians/rasterizer.h"

#include <torch/csrc/autograd/custom_function.h>

#include <array>
#include <string>
#include <vector>

#if SADSPLAT_HAVE_CUDA
#include <c10/cuda/CUDAGuard.h>
#endif

#include "raster_backend.h"
#include "sadsplat/common/cuda_support.h"
#include "sadsplat/common/error.h"
#include "sadsplat/gaussians/raster_math.h"
#include "sadsplat/gaussians/step_profile.h"
#include "sadsplat/gaussians/tile_list_capacity.h"

namespace sadsplat {
namespace gaussians {

raster::CameraParams raster::cameraParams(const RasterCamera& c) {
  raster::CameraParams p;
  const double q[4] = {c.qvec[0], c.qvec[1], c.qvec[2], c.qvec[3]};
  double R[9];
  raster::quatToRotation(q, R);
  for (int i = 0; i < 9; ++i) p.R[i] = R[i];
  for (int i = 0; i < 3; ++i) p.t[i] = c.tvec[i];
  p.fx = c.fx;
  p.fy = c.fy;
  p.cx = c.cx;
  p.cy = c.cy;
  p.width = c.width;
  p.height = c.height;
  p.near_plane = c.near_plane;
  p.orthographic = c.orthographic;
  return p;
}

namespace {

using raster::CameraParams;
using torch::autograd::AutogradContext;
using torch::autograd::variable_list;

std::vector<double> packCamera(const CameraParams& p) {
  std::vector<double> v(p.R.begin(), p.R.end());
  v.insert(v.end(), p.t.begin(), p.t.end());
  v.insert(v.end(), {p.fx, p.fy, p.cx, p.cy, double(p.width), double(p.height), p.near_plane,
                     p.orthographic ? 1.0 : 0.0});
  return v;
}

CameraParams unpackCamera(const std::vector<double>& v) {
  CameraParams p;
  for (int i = 0; i < 9; ++i) p.R[i] = v[i];
  for (int i = 0; i < 3; ++i) p.t[i] = v[9 + i];
  p.fx = v[12];
  p.fy = v[13];
  p.cx = v[14];
  p.cy = v[15];
  p.width = static_cast<int>(v[16]);
  p.height = static_cast<int>(v[17]);
  p.near_plane = v[18];
  p.orthographic = v[19] != 0;
  return p;
}

[[noreturn]] void noCuda() {
  throw Error("<render>", "device", "CPU tensors (this sadsplat build has no CUDA backend)",
              "CUDA tensors");
}

// The backend of tensor `t`: `cpu()` for a CPU tensor; for a CUDA tensor `cuda(stream)` on its
// device (a guard) and that device's current stream, or an error in a build without CUDA. The
// CUDA part is written with SADSPLAT_CUDA_PART, which leaves it out of builds without CUDA (its
// functions are not declared there).
template <typename Cpu, typename Cuda>
decltype(auto) onBackend(const at::Tensor& t, Cpu&& cpu, Cuda&& cuda) {
  if (t.is_cuda()) {
#if SADSPLAT_HAVE_CUDA
    const c10::cuda::CUDAGuard guard(t.device());
    return cuda(currentStream(t));
#else
    (void)cuda;
    noCuda();
#endif
  }
  return cpu();
}

#if SADSPLAT_HAVE_CUDA
#define SADSPLAT_CUDA_PART(...) [&](void* stream) { __VA_ARGS__ }
#else
#define SADSPLAT_CUDA_PART(...) [](void*) {}
#endif

// An output's gradient, or zeros of its shape when autograd passed none (made only then: the
// backward runs every step).
at::Tensor orZeros(const at::Tensor& grad, at::IntArrayRef sizes,
                   const at::TensorOptions& options) {
  return grad.defined() ? grad.contiguous() : at::zeros(sizes, options);
}

struct ProjectFunction : public torch::autograd::Function<ProjectFunction> {
  static variable_list forward(AutogradContext* ctx, const at::Tensor& means,
                               const at::Tensor& quats, const at::Tensor& log_scales,
                               const std::vector<double>& camera) {
    const CameraParams cam = unpackCamera(camera);
    const ScopedPhase phase("project");
    const at::Tensor m = means.contiguous(), q = quats.contiguous(), s = log_scales.contiguous();
    const raster::ProjectionResult r = onBackend(
        m, [&] { return raster::projectForwardCpu(m, q, s, cam); },
        SADSPLAT_CUDA_PART(return raster::projectForwardCuda(m, q, s, cam, stream);));
    ctx->save_for_backward({m, q, s, r.radii});
    ctx->saved_data["camera"] = camera;
    ctx->mark_non_differentiable({r.radii});
    return {r.means2d, r.conics, r.depths, r.radii};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const at::Tensor &m = saved[0], &q = saved[1], &s = saved[2], &radii = saved[3];
    const ScopedPhase phase("project backward");
    const CameraParams cam = unpackCamera(ctx->saved_data["camera"].toDoubleVector());
    const at::Tensor g_m2 = orZeros(grads[0], {m.size(0), 2}, m.options());
    const at::Tensor g_co = orZeros(grads[1], {m.size(0), 3}, m.options());
    const raster::ProjectionGrads g = onBackend(
        m,
        [&] {
          const at::Tensor g_d = orZeros(grads[2], {m.size(0)}, m.options());
          return raster::projectBackwardCpu(m, q, s, radii, cam, g_m2, g_co, g_d);
        },
        SADSPLAT_CUDA_PART(
            // Training renders no depth: the CUDA kernel takes its missing gradient as zeros.
            const at::Tensor g_d = grads[2].defined() ? grads[2].contiguous() : at::Tensor();
            return raster::projectBackwardCuda(m, q, s, radii, cam, g_m2, g_co, g_d, stream);));
    return {g.means, g.quats, g.log_scales, at::Tensor()};
  }
};

// Outputs {head, tail, alpha}: the image's first `split` channels as their own contiguous
// image (RGB), the others as a view of the rasterizer's [H, W, D] output (features, depth), and
// alpha. The backward writes the two parts' gradients into one [H, W, D] gradient image: slicing
// the image outside would cost, per render, two zero-filled full-size images and their sum.
struct RasterizeFunction : public torch::autograd::Function<RasterizeFunction> {
  static variable_list forward(AutogradContext* ctx, const at::Tensor& means2d,
                               const at::Tensor& conics, const at::Tensor& opacities,
                               const at::Tensor& values, const at::Tensor& radii,
                               const at::Tensor& depths, int64_t width, int64_t height,
                               int64_t split, TileListCapacity* capacity, bool closed_gates) {
    const ScopedPhase phase("rasterize");
    const at::Tensor m2 = means2d.contiguous(), co = conics.contiguous(),
                     op = opacities.contiguous(), val = values.contiguous();
    const int w = static_cast<int>(width), h = static_cast<int>(height);
    raster::RasterResult r = onBackend(
        m2,
        [&] {
          return raster::rasterizeForwardCpu(m2, co, op, val, radii.contiguous(),
                                             depths.contiguous(), w, h);
        },
        SADSPLAT_CUDA_PART(return raster::rasterizeForwardCuda(m2, co, op, val, radii.contiguous(),
                                                               depths.contiguous(), w, h, capacity,
                                                               stream);));
    ctx->save_for_backward({m2, co, op, val});
    // alpha is also an output: keeping the output itself in saved_data would make a reference
    // cycle output -> grad_fn -> ctx -> output and leak every graph (~8 MB per 800x450 render
    // on the GPU). The backward only needs the values.
    ctx->saved_data["alpha"] = r.alpha.detach();
    ctx->saved_data["last"] = r.last;
    ctx->saved_data["tile_ranges"] = r.binning.tile_ranges;
    ctx->saved_data["gaussian_ids"] = r.binning.gaussian_ids;
    ctx->saved_data["warps_packed"] = r.binning.warps_packed;
    ctx->saved_data["split"] = split;
    ctx->saved_data["closed_gates"] = closed_gates;
    const int64_t D = r.image.size(2);
    return {r.image.slice(2, 0, split).contiguous(), r.image.slice(2, split, D), r.alpha};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    raster::RasterResult fwd;
    const ScopedPhase phase("rasterize backward");
    fwd.alpha = ctx->saved_data["alpha"].toTensor();
    fwd.last = ctx->saved_data["last"].toTensor();
    fwd.binning.tile_ranges = ctx->saved_data["tile_ranges"].toTensor();
    fwd.binning.gaussian_ids = ctx->saved_data["gaussian_ids"].toTensor();
    fwd.binning.warps_packed = ctx->saved_data["warps_packed"].toBool();
    fwd.closed_gates = ctx->saved_data["closed_gates"].toBool();
    const at::Tensor& val = saved[3];
    const int64_t split = ctx->saved_data["split"].toInt(), D = val.size(1);
    at::Tensor g_img;
    if (split == 0 && grads[1].defined()) {
      g_img = grads[1].contiguous();
    } else if (split > 0 && split < D && grads[0].defined() && grads[1].defined()) {
      g_img = at::cat({grads[0], grads[1]}, 2);  // one operator call, the same values
    } else {
      g_img = at::empty({fwd.alpha.size(0), fwd.alpha.size(1), D}, val.options());
      const std::array<std::pair<int64_t, int64_t>, 2> parts{{{0, split}, {split, D}}};
      for (int k = 0; k < 2; ++k) {
        if (parts[k].first == parts[k].second) continue;
        at::Tensor part = g_img.slice(2, parts[k].first, parts[k].second);
        if (grads[k].defined()) {
          part.copy_(grads[k]);
        } else {
          part.zero_();
        }
      }
    }
    const raster::RasterGrads g = onBackend(
        val,
        [&] {
          const at::Tensor g_alpha = orZeros(grads[2], fwd.alpha.sizes(), fwd.alpha.options());
          return raster::rasterizeBackwardCpu(saved[0], saved[1], saved[2], val, fwd, g_img,
                                              g_alpha);
        },
        SADSPLAT_CUDA_PART(
            // Alpha without a gradient (a black background): the CUDA kernel takes it as zeros.
            const at::Tensor g_alpha = grads[2].defined() ? grads[2].contiguous() : at::Tensor();
            return raster::rasterizeBackwardCuda(saved[0], saved[1], saved[2], val, fwd, g_img,
                                                 g_alpha, stream);));
    // No gradient for radii, depths, width, height, split, the tile-list capacity and the flag.
    return {g.means2d,    g.conics,     g.opacities,  g.values,     at::Tensor(), at::Tensor(),
            at::Tensor(), at::Tensor(), at::Tensor(), at::Tensor(), at::Tensor()};
  }
};

// An SH part as the backends read it (raster::ShParts): row-major rows, any distance apart.
at::Tensor shRowsReadable(const at::Tensor& part) {
  const bool rows = part.stride(2) == 1 && (part.size(1) <= 1 || part.stride(1) == 3);
  return rows ? part : part.contiguous();
}

// The SH coefficients in two parts (raster::ShParts): the first and the others, each part's
// gradient its own contiguous tensor.
struct ShFunction : public torch::autograd::Function<ShFunction> {
  // camera: centre x, y, z and the SH degree.
  static variable_list forward(AutogradContext* ctx, const at::Tensor& sh_dc,
                               const at::Tensor& sh_rest, const at::Tensor& means,
                               const std::vector<double>& camera) {
    const raster::ShParts sh{shRowsReadable(sh_dc), shRowsReadable(sh_rest)};
    const at::Tensor m = means.contiguous();
    const ScopedPhase phase("SH");
    const std::array<double, 3> campos{camera[0], camera[1], camera[2]};
    const int degree = static_cast<int>(camera[3]);
    const at::Tensor colors = onBackend(
        m, [&] { return raster::shForwardCpu(sh, m, campos, degree); },
        SADSPLAT_CUDA_PART(return raster::shForwardCuda(sh, m, campos, degree, stream);));
    ctx->save_for_backward({sh.dc, sh.rest, m});
    ctx->saved_data["camera"] = camera;
    return {colors};
  }

  static variable_list backward(AutogradContext* ctx, variable_list grads) {
    const auto saved = ctx->get_saved_variables();
    const auto camera = ctx->saved_data["camera"].toDoubleVector();
    const ScopedPhase phase("SH backward");
    const std::array<double, 3> campos{camera[0], camera[1], camera[2]};
    const int degree = static_cast<int>(camera[3]);
    const raster::ShParts sh{saved[0], saved[1]};
    const at::Tensor& m = saved[2];
    const at::Tensor g = orZeros(grads[0], {m.size(0), 3}, m.options());
    const raster::ShGrads out = onBackend(
        m, [&] { return raster::shBackwardCpu(sh, m, campos, degree, g); },
        SADSPLAT_CUDA_PART(return raster::shBackwardCuda(sh, m, campos, degree, g, stream);));
    return {out.dc, out.rest, out.means, at::Tensor()};
  }
};

void expectTensor(const at::Tensor& t, const char* name, int64_t n, std::vector<int64_t> tail,
                  const at::Tensor& reference) {
  std::string want = "[" + std::to_string(n);
  for (auto d : tail) want += ", " + (d < 0 ? std::string("*") : std::to_string(d));
  want += "] " + std::string(c10::toString(reference.scalar_type())) + " on " +
          reference.device().str();
  if (!t.defined()) throw Error("<render>", name, want, "undefined");
  bool ok = t.dim() == 1 + static_cast<int64_t>(tail.size()) && t.size(0) == n &&
            t.scalar_type() == reference.scalar_type() && t.device() == reference.device();
  for (std::size_t i = 0; ok && i < tail.size(); ++i) {
    ok = tail[i] < 0 || t.size(static_cast<int64_t>(i) + 1) == tail[i];
  }
  if (!ok) {
    std::string got = "[";
    for (int64_t i = 0; i < t.dim(); ++i) got += (i ? ", " : "") + std::to_string(t.size(i));
    got += "] " + std::string(c10::toString(t.scalar_type())) + " on " + t.device().str();
    throw Error("<render>", name, want, got);
  }
}

void validateCamera(const RasterCamera& c) {
  if (c.width <= 0 || c.height <= 0 || !(c.fx > 0) || !(c.fy > 0) || !(c.near_plane > 0)) {
    throw Error("<render>", "camera", "positive width, height, focal lengths and near plane",
                std::to_string(c.width) + "x" + std::to_string(c.height) +
                    " fx=" + std::to_string(c.fx) + " fy=" + std::to_string(c.fy));
  }
}

}  // namespace

RasterCamera RasterCamera::fromPinhole(const io::PinholeCamera& camera) {
  RasterCamera c;
  c.width = camera.width;
  c.height = camera.height;
  c.fx = camera.fx;
  c.fy = camera.fy;
  c.cx = camera.cx;
  c.cy = camera.cy;
  c.qvec = camera.qvec;
  c.tvec = camera.tvec;
  return c;
}

std::array<double, 3> RasterCamera::centre() const {
  const double q[4] = {qvec[0], qvec[1], qvec[2], qvec[3]};
  double R[9];
  raster::quatToRotation(q, R);
  std::array<double, 3> c{};
  for (int j = 0; j < 3; ++j) c[j] = -(R[j] * tvec[0] + R[3 + j] * tvec[1] + R[6 + j] * tvec[2]);
  return c;
}

void RasterCamera::setRotation(const std::array<double, 9>& R) {
  // Shepperd's method: the largest of w, x, y, z first, for accuracy.
  const double tr = R[0] + R[4] + R[8];
  if (tr > 0) {
    const double s = 2 * std::sqrt(1 + tr);
    qvec = {0.25 * s, (R[7] - R[5]) / s, (R[2] - R[6]) / s, (R[3] - R[1]) / s};
  } else if (R[0] > R[4] && R[0] > R[8]) {
    const double s = 2 * std::sqrt(1 + R[0] - R[4] - R[8]);
    qvec = {(R[7] - R[5]) / s, 0.25 * s, (R[1] + R[3]) / s, (R[2] + R[6]) / s};
  } else if (R[4] > R[8]) {
    const double s = 2 * std::sqrt(1 + R[4] - R[0] - R[8]);
    qvec = {(R[2] - R[6]) / s, (R[1] + R[3]) / s, 0.25 * s, (R[5] + R[7]) / s};
  } else {
    const double s = 2 * std::sqrt(1 + R[8] - R[0] - R[4]);
    qvec = {(R[3] - R[1]) / s, (R[2] + R[6]) / s, (R[5] + R[7]) / s, 0.25 * s};
  }
}

std::array<double, 3> RasterCamera::shViewpoint() const {
  if (!orthographic) return centre();
  // Every ray of an orthographic camera runs along its z axis (row 2 of R): a viewpoint far back
  // on that axis sees each Gaussian from that direction; at 1e7 units the direction is off by
  // under 1e-5 rad for a Gaussian 100 units from the axis.
  const double q[4] = {qvec[0], qvec[1], qvec[2], qvec[3]};
  double R[9];
  raster::quatToRotation(q, R);
  std::array<double, 3> c = centre();
  for (int j = 0; j < 3; ++j) c[j] -= 1e7 * R[6 + j];
  return c;
}

at::Tensor evaluateSh(const at::Tensor& sh, const at::Tensor& means,
                      const std::array<double, 3>& camera_centre, int degree) {
  return evaluateSh(sh, at::Tensor(), means, camera_centre, degree);
}

at::Tensor evaluateSh(const at::Tensor& sh, const at::Tensor& sh_rest, const at::Tensor& means,
                      const std::array<double, 3>& camera_centre, int degree) {
  if (degree < 0 || degree > 3) {
    throw Error("<render>", "sh_degree", "0..3", std::to_string(degree));
  }
  const int64_t n = means.size(0);
  expectTensor(means, "means", n, {3}, means);
  if (sh_rest.defined()) {
    expectTensor(sh, "sh", n, {1, 3}, means);
    expectTensor(sh_rest, "sh_rest", n, {-1, 3}, means);
  } else {
    expectTensor(sh, "sh", n, {-1, 3}, means);
  }
  const int64_t coefficients = sh_rest.defined() ? 1 + sh_rest.size(1) : sh.size(1);
  if (coefficients < shCoefficientsForDegree(degree)) {
    throw Error("<render>", "sh",
                "at least " + std::to_string(shCoefficientsForDegree(degree)) +
                    " coefficients for SH degree " + std::to_string(degree),
                std::to_string(coefficients));
  }
  // One [N, K, 3] tensor is read as two views of itself, the first coefficient and the others.
  const at::Tensor dc = sh_rest.defined() ? sh : sh.narrow(1, 0, 1);
  const at::Tensor rest = sh_rest.defined() ? sh_rest : sh.narrow(1, 1, coefficients - 1);
  return ShFunction::apply(
      dc, rest, means,
      std::vector<double>{camera_centre[0], camera_centre[1], camera_centre[2], double(degree)})[0];
}

std::array<at::Tensor, 4> projectGaussians(const at::Tensor& means, const at::Tensor& quats,
                                           const at::Tensor& log_scales,
                                           const RasterCamera& camera) {
  validateCamera(camera);
  const int64_t n = means.defined() ? means.size(0) : 0;
  expectTensor(means, "means", n, {3}, means);
  expectTensor(quats, "quats", n, {4}, means);
  expectTensor(log_scales, "log_scales", n, {3}, means);
  const auto out =
      ProjectFunction::apply(means, quats, log_scales, packCamera(raster::cameraParams(camera)));
  return {out[0], out[1], out[2], out[3]};
}

namespace {

// rasterizeToPixels with the image's first `split` channels apart (RasterizeFunction): returns
// {head [H, W, split], tail [H, W, D - split], alpha [H, W]}. closed_gates: negative opacities
// are closed gates (raster_backend.h).
std::array<at::Tensor, 3> splitRasterize(const at::Tensor& means2d, const at::Tensor& conics,
                                         const at::Tensor& opacities, const at::Tensor& values,
                                         const at::Tensor& radii, const at::Tensor& depths,
                                         int width, int height, int64_t split,
                                         TileListCapacity* capacity = nullptr,
                                         bool closed_gates = false) {
  const int64_t n = means2d.size(0);
  expectTensor(conics, "conics", n, {3}, means2d);
  expectTensor(opacities, "opacities", n, {}, means2d);
  expectTensor(values, "values", n, {-1}, means2d);
  expectTensor(depths, "depths", n, {}, means2d);
  const auto out =
      RasterizeFunction::apply(means2d, conics, opacities, values, radii, depths.detach(), width,
                               height, split, capacity, closed_gates);
  return {out[0], out[1], out[2]};
}

}  // namespace

std::array<at::Tensor, 2> rasterizeToPixels(const at::Tensor& means2d, const at::Tensor& conics,
                                            const at::Tensor& opacities, const at::Tensor& values,
                                            const at::Tensor& radii, const at::Tensor& depths,
                                            int width, int height) {
  const auto out =
      splitRasterize(means2d, conics, opacities, values, radii, depths, width, height, 0);
  return {out[1], out[2]};
}

namespace {

// The background where the Gaussians leave a pixel uncovered: rgb + (1 - alpha) * background.
// No device tensor is made for it on the way: a blocking host-to-device copy of the three values
// waited for the GPU's queue once per render. Black (the default) adds nothing (the same values
// as adding zeros), a grey is a scalar, a colour is copied without blocking.
at::Tensor composeBackground(const at::Tensor& rgb, const at::Tensor& alpha,
                             const std::array<float, 3>& background) {
  const auto [r, g, b] = background;
  if (r == 0 && g == 0 && b == 0) return rgb.contiguous();
  const at::Tensor uncovered = (1.0 - alpha).unsqueeze(2);
  if (r == g && g == b) return rgb + uncovered * double(r);
  const at::Tensor colour =
      at::tensor({double(r), double(g), double(b)}, rgb.options().device(at::kCPU))
          .to(rgb.device(), /*non_blocking=*/true);
  return rgb + uncovered * colour;
}

}  // namespace

RenderResult render(const GaussianParams& g, const RasterCamera& camera,
                    const RenderSettings& settings) {
  validateCamera(camera);
  if (!g.means.defined())
    throw Error("<render>", "means", "a defined [N, 3] tensor", "an undefined tensor");
  const int64_t n = g.means.size(0);
  if (g.means.scalar_type() != at::kFloat && g.means.scalar_type() != at::kDouble) {
    throw Error("<render>", "means", "float32 or float64", c10::toString(g.means.scalar_type()));
  }
  if (settings.sh_degree < 0 || settings.sh_degree > 3) {
    throw Error("<render>", "sh_degree", "0..3", std::to_string(settings.sh_degree));
  }
  expectTensor(g.opacity_logits, "opacity_logits", n, {}, g.means);
  if (g.features.defined()) expectTensor(g.features, "features", n, {-1}, g.means);
  const at::Tensor features =
      g.features.defined() && settings.features ? g.features : at::zeros({n, 0}, g.means.options());

  auto [means2d, conics, depths, radii] = projectGaussians(g.means, g.quats, g.log_scales, camera);
  const at::Tensor colors =
      evaluateSh(g.sh, g.sh_rest, g.means, camera.shViewpoint(), settings.sh_degree);
  const at::Tensor values = settings.depth ? at::cat({colors, features, depths.unsqueeze(1)}, 1)
                            : features.size(1) > 0 ? at::cat({colors, features}, 1)
                                                   : colors;
  at::Tensor opacities = at::sigmoid(g.opacity_logits);
  if (g.opacity_gate.defined()) {
    expectTensor(g.opacity_gate, "opacity_gate", n, {}, g.means);
    const at::Tensor open = opacities;
    opacities = opacities * g.opacity_gate;
    if (settings.closed_gate_gradients) {
      // A closed gate goes to the backends as its negative opacity (raster_backend.h); the
      // subtracted part is detached, so gradients flow through opacity x gate as without it.
      opacities = opacities - (open * (g.opacity_gate == 0)).detach();
    }
  }
  // RGB apart from the features (and depth): the losses' gradients reach the rasterizer without
  // a slice backward of the whole image.
  const bool closed_gates = settings.closed_gate_gradients && g.opacity_gate.defined();
  auto [rgb, rest, alpha] =
      splitRasterize(means2d, conics, opacities, values, radii, depths, camera.width, camera.height,
                     3, settings.tile_capacity, closed_gates);
  const int64_t C = features.size(1);
  RenderResult result;
  result.rgb = composeBackground(rgb, alpha, settings.background);
  result.features = settings.depth ? rest.slice(2, 0, C) : rest;
  if (settings.depth) {
    const at::Tensor depth_sum = rest.select(2, C);
    result.depth = at::where(alpha > 0, depth_sum / alpha.clamp_min(1e-10), at::zeros_like(alpha));
  }
  result.alpha = alpha;
  result.means2d = means2d;
  result.radii = radii;
  return result;
}

}  // namespace gaussians
}  // namespace sadsplat
