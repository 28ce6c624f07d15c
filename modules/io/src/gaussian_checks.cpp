#include "sadsplat/io/gaussian_checks.h"

#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstring>
#include <sstream>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace io {
namespace {

std::string text(float v) {
  std::ostringstream out;
  out << v;
  return out.str();
}

// The kinds of values a Gaussian holds, with the range each must lie in.
enum class Range { kAny, kPosition, kLogScale };

struct Field {
  const char* name;  // PLY name; indexed fields get their index appended
  int count;         // 0: a single value without index
  std::size_t offset;
  Range range;
};

// Every float of a Gaussian but the opacity, which checkReadGaussians treats apart.
const Field kFields[] = {
    {"x", 0, offsetof(GaussianPoint, x), Range::kPosition},
    {"y", 0, offsetof(GaussianPoint, y), Range::kPosition},
    {"z", 0, offsetof(GaussianPoint, z), Range::kPosition},
    {"scale_", 3, offsetof(GaussianPoint, scale), Range::kLogScale},
    {"rot_", 4, offsetof(GaussianPoint, rot), Range::kAny},
    {"f_dc_", 3, offsetof(GaussianPoint, f_dc), Range::kAny},
    {"f_rest_", 3 * kShRestPerChannel, offsetof(GaussianPoint, f_rest), Range::kAny},
    {"feature_", kFeatureDim, offsetof(GaussianPoint, feature), Range::kAny},
    {"log_alpha", 0, offsetof(GaussianPoint, log_alpha), Range::kAny},
    {"confidence", 0, offsetof(GaussianPoint, confidence), Range::kAny},
    {"nx", 0, offsetof(GaussianPoint, nx), Range::kAny},
    {"ny", 0, offsetof(GaussianPoint, ny), Range::kAny},
    {"nz", 0, offsetof(GaussianPoint, nz), Range::kAny},
};

void checkOne(const std::string& path, std::size_t i, const GaussianPoint& p) {
  const auto* base = reinterpret_cast<const unsigned char*>(&p);
  for (const Field& f : kFields) {
    for (int k = 0; k < std::max(1, f.count); ++k) {
      float v;
      std::memcpy(&v, base + f.offset + sizeof(float) * k, sizeof(float));
      const bool finite = std::isfinite(v);
      const bool in_range = f.range == Range::kPosition   ? std::fabs(v) <= kMaxAbsPosition
                            : f.range == Range::kLogScale ? std::fabs(v) <= kMaxAbsLogScale
                                                          : true;
      if (finite && in_range) continue;
      // The message is built only for the value that fails (this runs for every value).
      const std::string where = "Gaussian " + std::to_string(i) + " " + f.name +
                                (f.count > 0 ? std::to_string(k) : std::string());
      if (!finite) throw Error(path, where, "a finite number", text(v));
      throw Error(path, where,
                  f.range == Range::kPosition ? "a coordinate within +-1e7 (plausible metres)"
                                              : "a log-scale within +-50",
                  text(v));
    }
  }
}

}  // namespace

GaussianReadReport checkReadGaussians(const std::string& path,
                                      pcl::PointCloud<GaussianPoint>& cloud) {
  GaussianReadReport report;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    GaussianPoint& p = cloud[i];
    if (std::isinf(p.opacity)) {
      p.opacity = p.opacity > 0 ? kMaxOpacityLogit : -kMaxOpacityLogit;
      ++report.clamped_opacities;
    }
    if (std::isnan(p.opacity)) {
      throw Error(path, "Gaussian " + std::to_string(i) + " opacity", "a number", "NaN");
    }
    checkOne(path, i, p);
  }
  return report;
}

void checkWritableGaussians(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    if (!std::isfinite(cloud[i].opacity)) {
      throw Error(path, "Gaussian " + std::to_string(i) + " opacity", "a finite number",
                  text(cloud[i].opacity));
    }
    checkOne(path, i, cloud[i]);
  }
}

}  // namespace io
}  // namespace sadsplat
