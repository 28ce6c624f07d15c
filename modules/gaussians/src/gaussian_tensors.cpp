#include "sadsplat/gaussians/gaussian_tensors.h"

#include <string>
#include <vector>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace gaussians {
namespace {

std::string shapeOf(const at::Tensor& t) {
  if (!t.defined()) return "undefined";
  std::string s = "[";
  for (int64_t i = 0; i < t.dim(); ++i) s += (i ? ", " : "") + std::to_string(t.size(i));
  return s + "] " + std::string(t.dtype().name()) + " on " + t.device().str();
}

void expectShape(const at::Tensor& t, const char* name, std::vector<int64_t> shape,
                 at::ScalarType dtype, const at::Device& device) {
  bool ok = t.defined() && t.dim() == static_cast<int64_t>(shape.size()) &&
            t.scalar_type() == dtype && t.device() == device;
  for (std::size_t i = 0; ok && i < shape.size(); ++i) {
    ok = shape[i] < 0 || t.size(static_cast<int64_t>(i)) == shape[i];
  }
  if (!ok) {
    std::string want = "[";
    for (std::size_t i = 0; i < shape.size(); ++i) {
      want += (i ? ", " : "") + (shape[i] < 0 ? std::string("*") : std::to_string(shape[i]));
    }
    want += "] " + std::string(c10::toString(dtype)) + " on " + device.str();
    throw Error("<GaussianTensors>", name, want, shapeOf(t));
  }
}

}  // namespace

GaussianTensors GaussianTensors::to(const at::Device& device) const {
  GaussianTensors out;
  out.means = means.to(device);
  out.normals = normals.to(device);
  out.sh_dc = sh_dc.to(device);
  out.sh_rest = sh_rest.to(device);
  out.opacity_logit = opacity_logit.to(device);
  out.log_scales = log_scales.to(device);
  out.rotations = rotations.to(device);
  out.features = features.to(device);
  out.log_alpha = log_alpha.to(device);
  out.confidence = confidence.to(device);
  out.labels = labels.to(device);
  return out;
}

void GaussianTensors::validate() const {
  if (!means.defined())
    throw Error("<GaussianTensors>", "means", "a defined [N, 3] tensor", "an undefined tensor");
  const int64_t n = means.size(0);
  const at::Device d = means.device();
  const auto f = at::kFloat;
  expectShape(means, "means", {n, 3}, f, d);
  expectShape(normals, "normals", {n, 3}, f, d);
  expectShape(sh_dc, "sh_dc", {n, 1, 3}, f, d);
  expectShape(sh_rest, "sh_rest", {n, kShRestPerChannel, 3}, f, d);
  expectShape(opacity_logit, "opacity_logit", {n}, f, d);
  expectShape(log_scales, "log_scales", {n, 3}, f, d);
  expectShape(rotations, "rotations", {n, 4}, f, d);
  expectShape(features, "features", {n, -1}, f, d);
  if (features.size(1) > kFeatureDim) {
    throw Error("<GaussianTensors>", "features",
                "at most " + std::to_string(kFeatureDim) + " channels", shapeOf(features));
  }
  expectShape(log_alpha, "log_alpha", {n}, f, d);
  expectShape(confidence, "confidence", {n}, f, d);
  expectShape(labels, "labels", {n}, at::kLong, d);
}

GaussianTensors fromCloud(const pcl::PointCloud<GaussianPoint>& cloud, const at::Device& device,
                          int feature_dim) {
  if (feature_dim < 0 || feature_dim > kFeatureDim) {
    throw Error("<fromCloud>", "feature_dim", "0.." + std::to_string(kFeatureDim),
                std::to_string(feature_dim));
  }
  const auto n = static_cast<int64_t>(cloud.size());
  const auto opts = at::TensorOptions().dtype(at::kFloat);
  GaussianTensors t;
  t.means = at::empty({n, 3}, opts);
  t.normals = at::empty({n, 3}, opts);
  t.sh_dc = at::empty({n, 1, 3}, opts);
  t.sh_rest = at::empty({n, kShRestPerChannel, 3}, opts);
  t.opacity_logit = at::empty({n}, opts);
  t.log_scales = at::empty({n, 3}, opts);
  t.rotations = at::empty({n, 4}, opts);
  t.features = at::empty({n, feature_dim}, opts);
  t.log_alpha = at::empty({n}, opts);
  t.confidence = at::empty({n}, opts);
  t.labels = at::empty({n}, at::TensorOptions().dtype(at::kLong));

  float* means = t.means.data_ptr<float>();
  float* normals = t.normals.data_ptr<float>();
  float* dc = t.sh_dc.data_ptr<float>();
  float* rest = t.sh_rest.data_ptr<float>();
  float* opacity = t.opacity_logit.data_ptr<float>();
  float* scales = t.log_scales.data_ptr<float>();
  float* rots = t.rotations.data_ptr<float>();
  float* feats = t.features.data_ptr<float>();
  float* log_alpha = t.log_alpha.data_ptr<float>();
  float* confidence = t.confidence.data_ptr<float>();
  int64_t* labels = t.labels.data_ptr<int64_t>();
  for (int64_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[static_cast<std::size_t>(i)];
    means[i * 3 + 0] = p.x;
    means[i * 3 + 1] = p.y;
    means[i * 3 + 2] = p.z;
    normals[i * 3 + 0] = p.nx;
    normals[i * 3 + 1] = p.ny;
    normals[i * 3 + 2] = p.nz;
    for (int c = 0; c < 3; ++c) {
      dc[i * 3 + c] = p.f_dc[c];
      for (int k = 0; k < kShRestPerChannel; ++k) {
        rest[(i * kShRestPerChannel + k) * 3 + c] = p.f_rest[c * kShRestPerChannel + k];
      }
      scales[i * 3 + c] = p.scale[c];
    }
    opacity[i] = p.opacity;
    for (int k = 0; k < 4; ++k) rots[i * 4 + k] = p.rot[k];
    for (int k = 0; k < feature_dim; ++k) feats[i * feature_dim + k] = p.feature[k];
    log_alpha[i] = p.log_alpha;
    confidence[i] = p.confidence;
    labels[i] = p.label == kUnlabelled ? -1 : static_cast<int64_t>(p.label);
  }
  return device.is_cpu() ? t : t.to(device);
}

pcl::PointCloud<GaussianPoint> toCloud(const GaussianTensors& tensors) {
  tensors.validate();
  const GaussianTensors t = tensors.to(at::kCPU);
  const int64_t n = t.size();
  const int64_t feature_dim = t.features.size(1);
  const at::Tensor means = t.means.contiguous(), normals = t.normals.contiguous(),
                   dc = t.sh_dc.contiguous(), rest = t.sh_rest.contiguous(),
                   opacity = t.opacity_logit.contiguous(), scales = t.log_scales.contiguous(),
                   rots = t.rotations.contiguous(), feats = t.features.contiguous(),
                   log_alpha = t.log_alpha.contiguous(), confidence = t.confidence.contiguous(),
                   labels = t.labels.contiguous();
  const float* m = means.data_ptr<float>();
  const float* nrm = normals.data_ptr<float>();
  const float* d = dc.data_ptr<float>();
  const float* r = rest.data_ptr<float>();
  const float* o = opacity.data_ptr<float>();
  const float* s = scales.data_ptr<float>();
  const float* q = rots.data_ptr<float>();
  const float* f = feats.data_ptr<float>();
  const float* la = log_alpha.data_ptr<float>();
  const float* cf = confidence.data_ptr<float>();
  const int64_t* lb = labels.data_ptr<int64_t>();

  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(static_cast<std::size_t>(n));
  for (int64_t i = 0; i < n; ++i) {
    GaussianPoint& p = cloud[static_cast<std::size_t>(i)];
    p.x = m[i * 3 + 0];
    p.y = m[i * 3 + 1];
    p.z = m[i * 3 + 2];
    p.nx = nrm[i * 3 + 0];
    p.ny = nrm[i * 3 + 1];
    p.nz = nrm[i * 3 + 2];
    for (int c = 0; c < 3; ++c) {
      p.f_dc[c] = d[i * 3 + c];
      for (int k = 0; k < kShRestPerChannel; ++k) {
        p.f_rest[c * kShRestPerChannel + k] = r[(i * kShRestPerChannel + k) * 3 + c];
      }
      p.scale[c] = s[i * 3 + c];
    }
    p.opacity = o[i];
    for (int k = 0; k < 4; ++k) p.rot[k] = q[i * 4 + k];
    for (int k = 0; k < kFeatureDim; ++k)
      p.feature[k] = k < feature_dim ? f[i * feature_dim + k] : 0.f;
    p.log_alpha = la[i];
    p.confidence = cf[i];
    if (lb[i] < -1 || lb[i] >= static_cast<int64_t>(kUnlabelled)) {
      throw Error("<GaussianTensors>", "labels[" + std::to_string(i) + "]",
                  "-1 (unlabelled) or a class id", std::to_string(lb[i]));
    }
    p.label = lb[i] < 0 ? kUnlabelled : static_cast<std::uint32_t>(lb[i]);
  }
  cloud.width = static_cast<std::uint32_t>(n);
  cloud.height = 1;
  cloud.is_dense = true;
  return cloud;
}

}  // namespace gaussians
}  // namespace sadsplat
