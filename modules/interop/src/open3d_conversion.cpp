#include "sadsplat/interop/open3d_conversion.h"

#include <cstring>
#include <string>
#include <vector>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace interop {
namespace {

namespace core = open3d::core;

// One scalar field of a GaussianPoint, by its PLY name and byte offset.
struct ScalarField {
  std::string name;
  std::size_t offset;
  bool required;
};

std::vector<ScalarField> scalarFields() {
  std::vector<ScalarField> f;
  const auto add = [&](const std::string& name, std::size_t offset, bool required) {
    f.push_back({name, offset, required});
  };
  for (int k = 0; k < 3; ++k) {
    add("f_dc_" + std::to_string(k), offsetof(GaussianPoint, f_dc) + 4 * k, true);
  }
  for (int k = 0; k < 3 * kShRestPerChannel; ++k) {
    add("f_rest_" + std::to_string(k), offsetof(GaussianPoint, f_rest) + 4 * k, false);
  }
  add("opacity", offsetof(GaussianPoint, opacity), true);
  for (int k = 0; k < 3; ++k) {
    add("scale_" + std::to_string(k), offsetof(GaussianPoint, scale) + 4 * k, true);
  }
  for (int k = 0; k < 4; ++k) {
    add("rot_" + std::to_string(k), offsetof(GaussianPoint, rot) + 4 * k, true);
  }
  for (int k = 0; k < kFeatureDim; ++k) {
    add("feature_" + std::to_string(k), offsetof(GaussianPoint, feature) + 4 * k, false);
  }
  add("log_alpha", offsetof(GaussianPoint, log_alpha), false);
  add("confidence", offsetof(GaussianPoint, confidence), false);
  return f;
}

const char* kOrigin = "<Open3D point cloud>";

// The attribute `key` as a contiguous CPU tensor of `dtype` with `columns` columns, or throws.
core::Tensor attribute(const open3d::t::geometry::PointCloud& cloud, const std::string& key,
                       core::Dtype dtype, int64_t columns, int64_t rows) {
  const core::Tensor& t = cloud.GetPointAttr(key);
  if (t.GetDtype() != dtype) {
    throw Error(kOrigin, "attribute " + key, dtype.ToString(), t.GetDtype().ToString());
  }
  if (t.NumDims() != 2 || t.GetShape(0) != rows || t.GetShape(1) != columns) {
    throw Error(kOrigin, "attribute " + key,
                "shape {" + std::to_string(rows) + ", " + std::to_string(columns) + "}",
                t.GetShape().ToString());
  }
  return t.To(core::Device("CPU:0")).Contiguous();
}

}  // namespace

open3d::t::geometry::PointCloud toOpen3d(const pcl::PointCloud<GaussianPoint>& cloud) {
  const int64_t n = static_cast<int64_t>(cloud.size());
  std::vector<float> xyz(3 * n), normals(3 * n);
  for (int64_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    xyz[3 * i] = p.x;
    xyz[3 * i + 1] = p.y;
    xyz[3 * i + 2] = p.z;
    normals[3 * i] = p.nx;
    normals[3 * i + 1] = p.ny;
    normals[3 * i + 2] = p.nz;
  }
  open3d::t::geometry::PointCloud out(core::Device("CPU:0"));
  out.SetPointPositions(core::Tensor(xyz, {n, 3}, core::Float32));
  out.SetPointNormals(core::Tensor(normals, {n, 3}, core::Float32));
  std::vector<float> column(n);
  for (const ScalarField& f : scalarFields()) {
    for (int64_t i = 0; i < n; ++i) {
      std::memcpy(&column[i], reinterpret_cast<const char*>(&cloud[i]) + f.offset, 4);
    }
    out.SetPointAttr(f.name, core::Tensor(column, {n, 1}, core::Float32));
  }
  std::vector<int32_t> labels(n);
  for (int64_t i = 0; i < n; ++i) std::memcpy(&labels[i], &cloud[i].label, 4);  // kUnlabelled: -1
  out.SetPointAttr("label", core::Tensor(labels, {n, 1}, core::Int32));
  return out;
}

pcl::PointCloud<GaussianPoint> fromOpen3d(const open3d::t::geometry::PointCloud& cloud) {
  if (!cloud.HasPointPositions()) {
    throw Error(kOrigin, "attribute positions", "present", "missing");
  }
  const int64_t n = cloud.GetPointPositions().GetShape(0);
  pcl::PointCloud<GaussianPoint> out;
  out.resize(static_cast<std::size_t>(n));
  const core::Tensor xyz = attribute(cloud, "positions", core::Float32, 3, n);
  const float* pxyz = xyz.GetDataPtr<float>();
  for (int64_t i = 0; i < n; ++i) {
    out[i].x = pxyz[3 * i];
    out[i].y = pxyz[3 * i + 1];
    out[i].z = pxyz[3 * i + 2];
  }
  if (cloud.HasPointNormals()) {
    const core::Tensor nrm = attribute(cloud, "normals", core::Float32, 3, n);
    const float* p = nrm.GetDataPtr<float>();
    for (int64_t i = 0; i < n; ++i) {
      out[i].nx = p[3 * i];
      out[i].ny = p[3 * i + 1];
      out[i].nz = p[3 * i + 2];
    }
  }
  bool all_rest = true;
  for (int k = 0; k < 3 * kShRestPerChannel; ++k) {
    all_rest = all_rest && cloud.HasPointAttr("f_rest_" + std::to_string(k));
  }
  for (const ScalarField& f : scalarFields()) {
    if (!cloud.HasPointAttr(f.name)) {
      if (f.required) throw Error(kOrigin, "attribute " + f.name, "present", "missing");
      continue;
    }
    if (f.name.rfind("f_rest_", 0) == 0 && !all_rest) continue;
    const core::Tensor t = attribute(cloud, f.name, core::Float32, 1, n);
    const float* p = t.GetDataPtr<float>();
    for (int64_t i = 0; i < n; ++i) {
      std::memcpy(reinterpret_cast<char*>(&out[i]) + f.offset, &p[i], 4);
    }
  }
  if (cloud.HasPointAttr("label")) {
    const core::Tensor t = attribute(cloud, "label", core::Int32, 1, n);
    const int32_t* p = t.GetDataPtr<int32_t>();
    for (int64_t i = 0; i < n; ++i) std::memcpy(&out[i].label, &p[i], 4);
  }
  out.width = static_cast<std::uint32_t>(n);
  out.height = 1;
  return out;
}

std::shared_ptr<open3d::geometry::PointCloud> toOpen3dLegacy(
    const pcl::PointCloud<pcl::PointXYZRGBL>& cloud, std::vector<int>* labels) {
  auto out = std::make_shared<open3d::geometry::PointCloud>();
  out->points_.reserve(cloud.size());
  out->colors_.reserve(cloud.size());
  if (labels) labels->clear();
  for (const auto& p : cloud) {
    out->points_.emplace_back(p.x, p.y, p.z);
    out->colors_.emplace_back(p.r / 255.0, p.g / 255.0, p.b / 255.0);
    if (labels) labels->push_back(p.label == kUnlabelled ? -1 : static_cast<int>(p.label));
  }
  return out;
}

}  // namespace interop
}  // namespace sadsplat
