#include "sadsplat/io/gaussian_ply.h"

#include <cmath>
#include <cstddef>
#include <cstring>
#include <sstream>

#include "ply_codec.h"
#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"

namespace sadsplat {
namespace io {
namespace {

using namespace ply;  // NOLINT: the container format this file reads

// Where a PLY vertex property goes in a GaussianPoint.
struct Target {
  enum Kind { kSkip, kFloat, kLabel } kind = kSkip;
  std::size_t float_offset = 0;  // byte offset of the float in GaussianPoint
};

#define SADSPLAT_FIELD_OFFSET(field) offsetof(GaussianPoint, field)

// Matches "<prefix><index>" and returns the index, or -1.
int indexedName(const std::string& name, const std::string& prefix) {
  if (name.size() <= prefix.size() || name.compare(0, prefix.size(), prefix) != 0) return -1;
  int index = 0;
  for (std::size_t i = prefix.size(); i < name.size(); ++i) {
    if (name[i] < '0' || name[i] > '9' || index > 100000) return -1;
    index = index * 10 + (name[i] - '0');
  }
  return index;
}

}  // namespace

pcl::PointCloud<GaussianPoint> readGaussianPly(const std::string& path, PlyFileInfo* info) {
  const std::string bytes = readWholeFile(path);
  const PlyHeader header = parseHeader(path, bytes);

  std::size_t vertex_index = header.elements.size();
  for (std::size_t i = 0; i < header.elements.size(); ++i) {
    if (header.elements[i].name == "vertex") vertex_index = i;
  }
  if (vertex_index == header.elements.size()) {
    throw Error(path, "header", "an \"element vertex\" line", "none");
  }
  const PlyElement& vertex = header.elements[vertex_index];

  PlyFileInfo found;
  found.format = header.format_name;
  found.num_vertices = vertex.count;

  // Map each vertex property to its place in GaussianPoint.
  std::vector<Target> targets(vertex.properties.size());
  int rest_count = 0;
  std::vector<bool> seen_required(14, false);  // x y z f_dc0..2 opacity scale0..2 rot0..3
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const PlyProperty& p = vertex.properties[i];
    if (p.is_list) {
      throw Error(path, "vertex property " + p.name, "a scalar property", "a list");
    }
    Target& t = targets[i];
    t.kind = Target::kFloat;
    const std::string& n = p.name;
    int k = -1;
    if (n == "x") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(x);
      seen_required[0] = true;
    } else if (n == "y") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(y);
      seen_required[1] = true;
    } else if (n == "z") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(z);
      seen_required[2] = true;
    } else if (n == "nx" || n == "ny" || n == "nz") {
      t.float_offset = n == "nx"   ? SADSPLAT_FIELD_OFFSET(nx)
                       : n == "ny" ? SADSPLAT_FIELD_OFFSET(ny)
                                   : SADSPLAT_FIELD_OFFSET(nz);
      found.has_normals = true;
    } else if ((k = indexedName(n, "f_dc_")) >= 0 && k < 3) {
      t.float_offset = SADSPLAT_FIELD_OFFSET(f_dc) + sizeof(float) * k;
      seen_required[3 + k] = true;
    } else if ((k = indexedName(n, "f_rest_")) >= 0) {
      t.kind = Target::kSkip;  // placed once the SH degree is known
      rest_count = std::max(rest_count, k + 1);
    } else if (n == "opacity") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(opacity);
      seen_required[6] = true;
    } else if ((k = indexedName(n, "scale_")) >= 0 && k < 3) {
      t.float_offset = SADSPLAT_FIELD_OFFSET(scale) + sizeof(float) * k;
      seen_required[7 + k] = true;
    } else if ((k = indexedName(n, "rot_")) >= 0 && k < 4) {
      t.float_offset = SADSPLAT_FIELD_OFFSET(rot) + sizeof(float) * k;
      seen_required[10 + k] = true;
    } else if ((k = indexedName(n, "feature_")) >= 0) {
      if (k >= kFeatureDim) {
        throw Error(path, "vertex property " + n,
                    "at most " + std::to_string(kFeatureDim) + " feature_* properties",
                    "feature_" + std::to_string(k));
      }
      t.float_offset = SADSPLAT_FIELD_OFFSET(feature) + sizeof(float) * k;
      found.feature_dim = std::max(found.feature_dim, k + 1);
      found.has_semantic = true;
    } else if (n == "log_alpha") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(log_alpha);
      found.has_semantic = true;
    } else if (n == "confidence") {
      t.float_offset = SADSPLAT_FIELD_OFFSET(confidence);
      found.has_semantic = true;
    } else if (n == "label") {
      t.kind = Target::kLabel;
      found.has_semantic = true;
    } else {
      t.kind = Target::kSkip;
      found.ignored_properties.push_back(n);
    }
  }
  static const char* kRequiredNames[14] = {"x",      "y",       "z",       "f_dc_0",  "f_dc_1",
                                           "f_dc_2", "opacity", "scale_0", "scale_1", "scale_2",
                                           "rot_0",  "rot_1",   "rot_2",   "rot_3"};
  for (int r = 0; r < 14; ++r) {
    if (!seen_required[r]) {
      throw Error(path, std::string("vertex property ") + kRequiredNames[r],
                  "present (a 3D Gaussian Splatting PLY has x y z f_dc_0..2 opacity scale_0..2 "
                  "rot_0..3)",
                  "missing");
    }
  }
  // Rest coefficients: 3 channels x ((d+1)^2 - 1), channel-major.
  int rest_per_channel = rest_count / 3;
  found.sh_degree = -1;
  for (int d = 0; d <= kMaxShDegree; ++d) {
    if (rest_count == 3 * (shCoefficientsForDegree(d) - 1)) found.sh_degree = d;
  }
  if (found.sh_degree < 0) {
    throw Error(path, "vertex properties f_rest_*", "0, 9, 24 or 45 of them (SH degree 0..3)",
                std::to_string(rest_count));
  }
  for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
    const int k = indexedName(vertex.properties[i].name, "f_rest_");
    if (k < 0) continue;
    const int channel = k / rest_per_channel;
    const int coeff = k % rest_per_channel;
    targets[i].kind = Target::kFloat;
    targets[i].float_offset =
        SADSPLAT_FIELD_OFFSET(f_rest) + sizeof(float) * (channel * kShRestPerChannel + coeff);
  }

  ValueDecoder decoder(path, bytes, header.data_offset, header.format);
  for (std::size_t e = 0; e < vertex_index; ++e) {
    skipElement(path, decoder, header.elements[e], header.format);
  }
  checkElementFits(path, decoder, vertex, header.format);

  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(vertex.count);
  for (std::size_t v = 0; v < vertex.count; ++v) {
    GaussianPoint& point = cloud[v];
    auto* base = reinterpret_cast<unsigned char*>(&point);
    for (std::size_t i = 0; i < vertex.properties.size(); ++i) {
      const PlyProperty& p = vertex.properties[i];
      const double value =
          decoder.next(p.type, "vertex " + std::to_string(v) + " property " + p.name);
      const Target& t = targets[i];
      if (t.kind == Target::kSkip) continue;
      // Checked as the float it becomes: a double of 1e300 or an ascii 1e39 is infinite then.
      // An infinite opacity is left to checkReadGaussians, which clamps it.
      const bool opacity = t.kind == Target::kFloat && t.float_offset == offsetof(GaussianPoint, opacity);
      if (std::isnan(value) || (!opacity && !std::isfinite(static_cast<float>(value)))) {
        throw Error(path, "vertex " + std::to_string(v) + " property " + p.name,
                    "a finite number within float range", std::to_string(value));
      }
      if (t.kind == Target::kLabel) {
        if (value == -1.0) {  // an `int label` (Open3D's type) marks "no class" with -1
          point.label = kUnlabelled;
          continue;
        }
        if (value < 0 || value > static_cast<double>(kUnlabelled) || value != std::floor(value)) {
          throw Error(path, "vertex " + std::to_string(v) + " property label",
                      "an unsigned integer class id", std::to_string(value));
        }
        point.label = static_cast<std::uint32_t>(value);
      } else {
        const float f = static_cast<float>(value);
        std::memcpy(base + t.float_offset, &f, sizeof(float));
      }
    }
    decoder.endItem();
  }
  // Elements after the vertices (a camera record, faces) are not used, but a header that
  // declares more of them than the file holds is a truncated or corrupt file.
  for (std::size_t e = vertex_index + 1; e < header.elements.size(); ++e) {
    skipElement(path, decoder, header.elements[e], header.format);
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  cloud.is_dense = true;
  found.clamped_opacities = checkReadGaussians(path, cloud).clamped_opacities;
  if (info != nullptr) *info = found;
  return cloud;
}

void writeGaussianPly(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                      const PlyWriteOptions& options) {
  if (options.sh_degree < 0 || options.sh_degree > kMaxShDegree) {
    throw Error(path, "sh_degree option", "0..3", std::to_string(options.sh_degree));
  }
  if (options.feature_dim < 0 || options.feature_dim > kFeatureDim) {
    throw Error(path, "feature_dim option", "0.." + std::to_string(kFeatureDim),
                std::to_string(options.feature_dim));
  }
  checkWritableGaussians(path, cloud);
  const int features = options.feature_dim;
  const int rest = shCoefficientsForDegree(options.sh_degree) - 1;

  std::ostringstream header;
  header << "ply\nformat binary_little_endian 1.0\ncomment written by sadsplat\n"
         << "element vertex " << cloud.size() << "\n";
  for (const char* n : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) {
    header << "property float " << n << "\n";
  }
  for (int k = 0; k < 3 * rest; ++k) header << "property float f_rest_" << k << "\n";
  header << "property float opacity\n";
  for (int k = 0; k < 3; ++k) header << "property float scale_" << k << "\n";
  for (int k = 0; k < 4; ++k) header << "property float rot_" << k << "\n";
  if (options.semantic) {
    for (int k = 0; k < features; ++k) header << "property float feature_" << k << "\n";
    // `int`, not `uint`: Open3D's PLY reader skips uint properties. kUnlabelled is written as -1
    // (the same 32 bits).
    header << "property float log_alpha\nproperty float confidence\nproperty int label\n";
  }
  header << "end_header\n";
  const std::string header_text = header.str();

  // One record per vertex, all fields 4 bytes, little endian (the host order on x86-64/ARM).
  const std::size_t floats_per_record =
      9 + 3 * rest + 1 + 3 + 4 + (options.semantic ? features + 3 : 0);
  std::vector<float> record(floats_per_record);
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(header_text.data(), static_cast<std::streamsize>(header_text.size()));
    for (const GaussianPoint& p : cloud) {
      float* r = record.data();
      for (float v : {p.x, p.y, p.z, p.nx, p.ny, p.nz, p.f_dc[0], p.f_dc[1], p.f_dc[2]}) *r++ = v;
      for (int c = 0; c < 3; ++c) {
        for (int k = 0; k < rest; ++k) *r++ = p.f_rest[c * kShRestPerChannel + k];
      }
      *r++ = p.opacity;
      for (float v : p.scale) *r++ = v;
      for (float v : p.rot) *r++ = v;
      if (options.semantic) {
        for (int k = 0; k < features; ++k) *r++ = p.feature[k];
        *r++ = p.log_alpha;
        *r++ = p.confidence;
        std::memcpy(r++, &p.label, sizeof(float));
      }
      out.write(reinterpret_cast<const char*>(record.data()),
                static_cast<std::streamsize>(record.size() * sizeof(float)));
    }
  });
}

}  // namespace io
}  // namespace sadsplat
