#include "sadsplat/io/splat_formats.h"

#include <zlib.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"

namespace sadsplat {
namespace io {
namespace {

constexpr float kC0 = 0.28209479177387814f;  // SH degree-0 basis constant
constexpr std::uint32_t kSpzMagic = 0x5053474e;
constexpr float kSpzColorScale = 0.15f;
constexpr int kSpzFractionalBits = 12;
constexpr std::size_t kMaxGaussians = std::size_t{1} << 28;

std::uint8_t toByte(float v) {
  return static_cast<std::uint8_t>(std::clamp(std::round(v), 0.0f, 255.0f));
}
float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }
// The opacity logit of an 8-bit alpha, kept finite at 0 and 255.
float logitOfByte(std::uint8_t a) {
  const float p = std::clamp(a / 255.0f, 0.5f / 255.0f, 254.5f / 255.0f);
  return std::log(p / (1.0f - p));
}

// The normalised quaternion (w, x, y, z) of a point, identity when it is zero.
std::array<float, 4> unitQuaternion(const GaussianPoint& p) {
  const float n = std::sqrt(p.rot[0] * p.rot[0] + p.rot[1] * p.rot[1] + p.rot[2] * p.rot[2] +
                            p.rot[3] * p.rot[3]);
  if (!(n > 0)) return {1, 0, 0, 0};
  return {p.rot[0] / n, p.rot[1] / n, p.rot[2] / n, p.rot[3] / n};
}

void requireFinite(const std::string& path, std::size_t i, const GaussianPoint& p) {
  const float values[] = {p.x,        p.y,       p.z,       p.scale[0], p.scale[1],
                          p.scale[2], p.rot[0],  p.rot[1],  p.rot[2],   p.rot[3],
                          p.opacity,  p.f_dc[0], p.f_dc[1], p.f_dc[2]};
  for (float v : values) {
    if (!std::isfinite(v)) {
      throw Error(path, "Gaussian " + std::to_string(i), "finite values", "NaN or infinity");
    }
  }
}

std::vector<std::uint8_t> gzip(const std::string& path, const std::vector<std::uint8_t>& data) {
  z_stream s{};
  if (deflateInit2(&s, Z_DEFAULT_COMPRESSION, Z_DEFLATED, 16 + MAX_WBITS, 9, Z_DEFAULT_STRATEGY) !=
      Z_OK) {
    throw Error(path, "gzip", "zlib to initialise");
  }
  std::vector<std::uint8_t> out(deflateBound(&s, data.size()) + 64);
  s.next_in = const_cast<Bytef*>(data.data());
  s.avail_in = static_cast<uInt>(data.size());
  s.next_out = out.data();
  s.avail_out = static_cast<uInt>(out.size());
  const int rc = deflate(&s, Z_FINISH);
  deflateEnd(&s);
  if (rc != Z_STREAM_END) throw Error(path, "gzip", "the data compressed", "a zlib error");
  out.resize(out.size() - s.avail_out);
  return out;
}

// Inflates gzip data, refusing to produce more than `limit` bytes.
std::vector<std::uint8_t> gunzip(const std::string& path, const std::string& bytes,
                                 std::size_t limit) {
  z_stream s{};
  if (inflateInit2(&s, 16 + MAX_WBITS) != Z_OK) throw Error(path, "gzip", "zlib to initialise");
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(bytes.data()));
  s.avail_in = static_cast<uInt>(bytes.size());
  std::vector<std::uint8_t> out;
  std::uint8_t buffer[65536];
  int rc = Z_OK;
  while (rc != Z_STREAM_END) {
    s.next_out = buffer;
    s.avail_out = sizeof(buffer);
    rc = inflate(&s, Z_NO_FLUSH);
    if (rc != Z_OK && rc != Z_STREAM_END) {
      inflateEnd(&s);
      throw Error(path, "gzip data", "a valid gzip stream", "corrupt or truncated data");
    }
    const std::size_t produced = sizeof(buffer) - s.avail_out;
    if (out.size() + produced > limit) {
      inflateEnd(&s);
      throw Error(path, "gzip data", "at most " + std::to_string(limit) + " bytes uncompressed",
                  "more (a count in the header that does not match the data)");
    }
    out.insert(out.end(), buffer, buffer + produced);
    if (produced == 0 && s.avail_in == 0 && rc != Z_STREAM_END) {
      inflateEnd(&s);
      throw Error(path, "gzip data", "a complete gzip stream", "truncated data");
    }
  }
  inflateEnd(&s);
  return out;
}

}  // namespace

void writeSplat(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  std::vector<std::uint8_t> bytes(cloud.size() * 32);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const GaussianPoint& p = cloud[i];
    requireFinite(path, i, p);
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

pcl::PointCloud<GaussianPoint> readSplat(const std::string& path) {
  const std::string bytes = readWholeFile(path);
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
        throw Error(path, "Gaussian " + std::to_string(i) + " scale", "a positive finite value",
                    std::to_string(f[3 + k]));
      }
      p.scale[k] = std::log(f[3 + k]);
    }
    if (!std::isfinite(p.x) || !std::isfinite(p.y) || !std::isfinite(p.z)) {
      throw Error(path, "Gaussian " + std::to_string(i) + " position", "finite coordinates");
    }
    for (int c = 0; c < 3; ++c) p.f_dc[c] = (r[24 + c] / 255.0f - 0.5f) / kC0;
    p.opacity = logitOfByte(r[27]);
    for (int k = 0; k < 4; ++k) p.rot[k] = (r[28 + k] - 128.0f) / 128.0f;
  }
  cloud.width = static_cast<std::uint32_t>(cloud.size());
  cloud.height = 1;
  return cloud;
}

void writeSpz(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud, int sh_degree,
              int version) {
  if (sh_degree < 0 || sh_degree > kMaxShDegree) {
    throw Error(path, "sh_degree", "0..3", std::to_string(sh_degree));
  }
  if (version != 2 && version != 3) {
    throw Error(path, "SPZ version", "2 or 3", std::to_string(version));
  }
  const std::size_t rotation_bytes = version == 3 ? 4 : 3;
  const std::size_t n = cloud.size();
  const int rest = shCoefficientsForDegree(sh_degree) - 1;  // per channel
  std::vector<std::uint8_t> data(16 + n * (9 + 1 + 3 + 3 + rotation_bytes + 3 * rest));
  const std::uint32_t header[3] = {kSpzMagic, static_cast<std::uint32_t>(version),
                                   static_cast<std::uint32_t>(n)};
  std::memcpy(data.data(), header, 12);
  data[12] = static_cast<std::uint8_t>(sh_degree);
  data[13] = kSpzFractionalBits;
  data[14] = 0;  // flags
  data[15] = 0;  // reserved
  std::uint8_t* positions = data.data() + 16;
  std::uint8_t* alphas = positions + 9 * n;
  std::uint8_t* colors = alphas + n;
  std::uint8_t* scales = colors + 3 * n;
  std::uint8_t* rotations = scales + 3 * n;
  std::uint8_t* sh = rotations + rotation_bytes * n;
  const float fixed = static_cast<float>(1 << kSpzFractionalBits);
  for (std::size_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    requireFinite(path, i, p);
    const float xyz[3] = {p.x, p.y, p.z};
    for (int k = 0; k < 3; ++k) {
      if (std::fabs(xyz[k]) * fixed >= 8388607.0f) {
        throw Error(path, "Gaussian " + std::to_string(i) + " position",
                    "coordinates within +-2048 (24-bit fixed point with 12 fractional bits)",
                    std::to_string(xyz[k]));
      }
      const std::int32_t v = static_cast<std::int32_t>(std::lround(xyz[k] * fixed));
      for (int b = 0; b < 3; ++b) positions[9 * i + 3 * k + b] = (v >> (8 * b)) & 0xff;
    }
    alphas[i] = toByte(255.0f * sigmoid(p.opacity));
    for (int c = 0; c < 3; ++c) {
      colors[3 * i + c] = toByte(127.5f + kSpzColorScale * 255.0f * p.f_dc[c]);
      scales[3 * i + c] = toByte((p.scale[c] + 10.0f) * 16.0f);
    }
    // Version 3 rotation: SPZ's order (x, y, z, w); the index of the largest component, and
    // the other three as sign + 9-bit magnitude in units of 1/sqrt(2) (the largest is made
    // positive, so its sign needs no bit); the last component ends in the low bits.
    const auto u = unitQuaternion(p);
    if (version == 2) {  // x y z of the quaternion with w >= 0; w is derived on reading
      const float sign = u[0] < 0 ? -1.0f : 1.0f;
      for (int k = 0; k < 3; ++k) {
        rotations[3 * i + k] = toByte(127.5f + 127.5f * sign * u[1 + k]);
      }
    }
    const float q[4] = {u[1], u[2], u[3], u[0]};
    unsigned largest = 0;
    for (unsigned k = 1; k < 4; ++k) {
      if (std::fabs(q[k]) > std::fabs(q[largest])) largest = k;
    }
    const bool negate = q[largest] < 0;
    std::uint32_t comp = largest;
    for (unsigned k = 0; k < 4; ++k) {
      if (k == largest) continue;
      const std::uint32_t sign = (q[k] < 0) != negate ? 1u : 0u;
      const std::uint32_t mag = std::min<std::uint32_t>(
          511u, static_cast<std::uint32_t>(511.0f * std::fabs(q[k]) / 0.70710678f + 0.5f));
      comp = (comp << 10) | (sign << 9) | mag;
    }
    if (version == 3) {
      for (int b = 0; b < 4; ++b) rotations[4 * i + b] = (comp >> (8 * b)) & 0xff;
    }
    for (int k = 0; k < rest; ++k) {
      // Fewer significant bits for higher degrees (buckets of 8 and 16), as SPZ's own writer.
      const int bucket = k < 3 ? 8 : 16;
      for (int c = 0; c < 3; ++c) {
        int v = static_cast<int>(std::round(p.f_rest[c * kShRestPerChannel + k] * 128.0f)) + 128;
        v = (v + bucket / 2) / bucket * bucket;
        sh[(i * rest + k) * 3 + c] = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
      }
    }
  }
  const std::vector<std::uint8_t> packed = gzip(path, data);
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(packed.data()),
              static_cast<std::streamsize>(packed.size()));
  });
}

pcl::PointCloud<GaussianPoint> readSpz(const std::string& path) {
  const std::string bytes = readWholeFile(path);
  if (bytes.size() < 18 || static_cast<std::uint8_t>(bytes[0]) != 0x1f ||
      static_cast<std::uint8_t>(bytes[1]) != 0x8b) {
    throw Error(path, "gzip header", "an .spz file (gzip data starting 1f 8b)");
  }
  // Deflate expands at most ~1032:1; the header's count bounds the output further below.
  const std::size_t limit = std::min<std::size_t>(bytes.size() * 1040 + 4096, std::size_t{1} << 34);
  const std::vector<std::uint8_t> data = gunzip(path, bytes, limit);
  if (data.size() < 16) throw Error(path, "header", "16 bytes", std::to_string(data.size()));
  std::uint32_t header[3];
  std::memcpy(header, data.data(), 12);
  if (header[0] != kSpzMagic) throw Error(path, "magic", "0x5053474e (NGSP)");
  if (header[1] != 2 && header[1] != 3) {
    throw Error(path, "version", "2 or 3", std::to_string(header[1]));
  }
  const std::size_t n = header[2];
  const int degree = data[12];
  const int bits = data[13];
  if (n > kMaxGaussians) throw Error(path, "numPoints", "at most 2^28", std::to_string(n));
  if (degree > kMaxShDegree) throw Error(path, "shDegree", "0..3", std::to_string(degree));
  if (bits > 23) throw Error(path, "fractionalBits", "0..23", std::to_string(bits));
  const int rest = shCoefficientsForDegree(degree) - 1;
  const std::size_t rotation_bytes = header[1] == 3 ? 4 : 3;
  const std::size_t want = 16 + n * (9 + 1 + 3 + 3 + rotation_bytes + 3 * rest);
  if (data.size() != want) {
    throw Error(path, "data",
                std::to_string(want) + " bytes for " + std::to_string(n) +
                    " Gaussians of SH degree " + std::to_string(degree),
                std::to_string(data.size()));
  }
  const std::uint8_t* positions = data.data() + 16;
  const std::uint8_t* alphas = positions + 9 * n;
  const std::uint8_t* colors = alphas + n;
  const std::uint8_t* scales = colors + 3 * n;
  const std::uint8_t* rotations = scales + 3 * n;
  const std::uint8_t* sh = rotations + rotation_bytes * n;
  const float fixed = static_cast<float>(1 << bits);
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(n);
  for (std::size_t i = 0; i < n; ++i) {
    GaussianPoint& p = cloud[i];
    float xyz[3];
    for (int k = 0; k < 3; ++k) {
      const std::uint8_t* b = positions + 9 * i + 3 * k;
      std::int32_t v = b[0] | (b[1] << 8) | (b[2] << 16);
      if (v & 0x800000) v |= ~0xffffff;  // sign-extend 24 bits
      xyz[k] = static_cast<float>(v) / fixed;
    }
    p.x = xyz[0];
    p.y = xyz[1];
    p.z = xyz[2];
    p.opacity = logitOfByte(alphas[i]);
    for (int c = 0; c < 3; ++c) {
      p.f_dc[c] = (colors[3 * i + c] - 127.5f) / (kSpzColorScale * 255.0f);
      p.scale[c] = scales[3 * i + c] / 16.0f - 10.0f;
    }
    if (rotation_bytes == 3) {
      float xyzq[3], norm2 = 0;
      for (int k = 0; k < 3; ++k) {
        xyzq[k] = rotations[3 * i + k] / 127.5f - 1.0f;
        norm2 += xyzq[k] * xyzq[k];
      }
      p.rot[0] = std::sqrt(std::max(0.0f, 1.0f - norm2));
      for (int k = 0; k < 3; ++k) p.rot[1 + k] = xyzq[k];
    } else {
      // Version 3: the index of the largest component (2 bits), then the three others as
      // sign + 9-bit magnitude in units of 1/sqrt(2), last component in the low bits.
      const std::uint8_t* b = rotations + 4 * i;
      std::uint32_t comp =
          b[0] | (b[1] << 8) | (b[2] << 16) | (static_cast<std::uint32_t>(b[3]) << 24);
      const unsigned largest = comp >> 30;
      float q[4];  // x y z w (SPZ's order)
      float sum = 0;
      for (int k = 3; k >= 0; --k) {
        if (static_cast<unsigned>(k) == largest) continue;
        const float mag = static_cast<float>(comp & 511u) / 511.0f * 0.70710678f;
        const bool negative = (comp >> 9) & 1u;
        comp >>= 10;
        q[k] = negative ? -mag : mag;
        sum += q[k] * q[k];
      }
      q[largest] = std::sqrt(std::max(0.0f, 1.0f - sum));
      p.rot[0] = q[3];
      p.rot[1] = q[0];
      p.rot[2] = q[1];
      p.rot[3] = q[2];
    }
    for (int k = 0; k < rest; ++k) {
      for (int c = 0; c < 3; ++c) {
        p.f_rest[c * kShRestPerChannel + k] = (sh[(i * rest + k) * 3 + c] - 128.0f) / 128.0f;
      }
    }
  }
  cloud.width = static_cast<std::uint32_t>(n);
  cloud.height = 1;
  return cloud;
}

}  // namespace io
}  // namespace sadsplat
