// The `.splat` format of antimatter15's WebGL viewer (see splat_formats.h).
#include <cmath>
#include <cstring>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/splat_formats.h"
#include "splat_codec_support.h"

namespace sadsplat {
namespace io {

using namespace splat_codec;  // NOLINT: the codec helpers of this family of formats

void writeSplat(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  // The check bounds |log-scale| by 50: exp() of it is a positive, finite float32, so every
  // file written here reads back.
  checkWritableGaussians(path, cloud);
  std::vector<std::uint8_t> bytes(cloud.size() * 32);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const GaussianPoint& p = cloud[i];
    std::uint8_t* r = bytes.data() + 32 * i;
    const float f[6] = {
        p.x, p.y, p.z, std::exp(p.scale[0]), std::exp(p.scale[1]), std::exp(p.scale[2])};
    std::memcpy(r, f, 24);
    for (int c = 0; c < 3; ++c) r[24 + c] = toByte(255.0f * (0.5f + kC0 * p.f_dc[c]));
    r[27] = toByte(255.0f * sigmoid(p.opacity));
    const auto q = unitQuaternion(p);
    for (int k = 0; k < 4; ++k) r[28 + k] = toByte(128.0f + 128.0f * q[k]);
  }
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(bytes.data()),
              static_cast<std::streamsize>(bytes.size()));
  });
}

pcl::PointCloud<GaussianPoint> readSplat(const std::string& path, SplatFileInfo* info) {
  const std::string bytes = readWholeFile(path);
  if (bytes.empty()) {
    throw Error(path, "size", "at least one 32-byte record (a .splat has no header)", "0 bytes");
  }
  if (bytes.size() % 32 != 0) {
    throw Error(path, "size", "a multiple of 32 bytes (one 32-byte record per Gaussian)",
                std::to_string(bytes.size()) + " bytes");
  }
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(bytes.size() / 32);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto* r = reinterpret_cast<const std::uint8_t*>(bytes.data()) + 32 * i;
    float f[6];
    std::memcpy(f, r, 24);
    GaussianPoint& p = cloud[i];
    p.x = f[0];
    p.y = f[1];
    p.z = f[2];
    for (int k = 0; k < 3; ++k) {
      if (!(f[3 + k] > 0) || !std::isfinite(f[3 + k])) {
        throw Error(path, "Gaussian " + std::to_string(i) + " scale_" + std::to_string(k),
                    "a positive finite value", std::to_string(f[3 + k]));
      }
      p.scale[k] = std::log(f[3 + k]);
    }
    for (int c = 0; c < 3; ++c) p.f_dc[c] = (r[24 + c] / 255.0f - 0.5f) / kC0;
    p.opacity = logitOfAlpha(r[27] / 255.0f);
    for (int k = 0; k < 4; ++k) p.rot[k] = (r[28 + k] - 128.0f) / 128.0f;
  }
  finishCloud(cloud);
  const GaussianReadReport report = checkReadGaussians(path, cloud);
  if (info != nullptr) info->clamped_opacities = report.clamped_opacities;
  return cloud;
}

}  // namespace io
}  // namespace sadsplat
