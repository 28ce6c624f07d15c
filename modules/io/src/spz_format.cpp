// Niantic's SPZ format, versions 2 and 3 (gzip, one stream) and 4 (zstd, one stream per
// attribute), as its reference implementation (nianticlabs/spz, load-spz.cc) writes it. SPZ
// stores RUB axes (x right, y up, z back); sadsplat's clouds and PLY files are RDF (y down,
// z forward), so y and z are negated on the way in and out, with the quaternion and the SH
// coefficients that change sign under that flip.
#include <algorithm>
#include <cmath>
#include <cstring>
#include <vector>

#include "compression.h"
#include "sadsplat/common/error.h"
#include "sadsplat/common/sh_degree.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/splat_formats.h"
#include "splat_codec_support.h"

namespace sadsplat {
namespace io {
namespace {

using namespace splat_codec;  // NOLINT: the codec helpers of this family of formats

constexpr std::uint32_t kMagic = 0x5053474e;  // "NGSP"
constexpr float kColorScale = 0.15f;
constexpr int kDefaultFractionalBits = 12;
constexpr std::uint8_t kFlagAntialiased = 0x1;
constexpr std::uint8_t kFlagExtensions = 0x2;
constexpr std::size_t kLegacyHeaderBytes = 16;
constexpr std::size_t kV4HeaderBytes = 32;
constexpr std::uint64_t kMaxPoints = std::uint64_t{1} << 28;
// Version 4's bound on a stream's compression ratio (as the reference reader's): a header that
// claims more Gaussians than the file could hold at that ratio is refused before any allocation.
constexpr std::uint64_t kMaxZstdRatio = 1024;

// Sign of each SH rest coefficient (degrees 1..3, gsplat's basis order) under y -> -y, z -> -z:
// the basis functions odd in y or z change sign, those even in both keep it.
constexpr float kRdfRubShSign[15] = {-1, -1, 1, -1, 1, 1, -1, 1, -1, 1, -1, -1, 1, -1, 1};

// The cloud turned 180 degrees about x (y -> -y, z -> -z): what RDF <-> RUB does, applied twice
// to keep a cloud's axes as stored.
void turnAboutX(pcl::PointCloud<GaussianPoint>& cloud) {
  for (GaussianPoint& p : cloud) {
    p.y = -p.y;
    p.z = -p.z;
    p.rot[2] = -p.rot[2];
    p.rot[3] = -p.rot[3];
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < kShRestPerChannel; ++k) p.f_rest[c * kShRestPerChannel + k] *= kRdfRubShSign[k];
    }
  }
}

std::size_t shDim(int degree) {
  return static_cast<std::size_t>(shCoefficientsForDegree(degree) - 1);
}

// The byte layout of one file's attribute arrays.
struct Layout {
  std::size_t n = 0;
  int degree = 0;          // SH degree stored in the file (0..4)
  std::size_t rotation = 4;  // bytes per rotation: 3 (version 2) or 4 (versions 3, 4)
  std::size_t positions() const { return 9 * n; }
  std::size_t alphas() const { return n; }
  std::size_t colors() const { return 3 * n; }
  std::size_t scales() const { return 3 * n; }
  std::size_t rotations() const { return rotation * n; }
  std::size_t sh() const { return 3 * shDim(degree) * n; }
  std::size_t total() const {
    return positions() + alphas() + colors() + scales() + rotations() + sh();
  }
  // The attribute streams in file order, with their sizes (version 4 omits empty ones).
  std::vector<std::size_t> streams() const {
    std::vector<std::size_t> s = {positions(), alphas(), colors(), scales(), rotations()};
    if (sh() > 0) s.push_back(sh());
    return s;
  }
};

// The fixed-point precision for the positions: 12 fractional bits (the reference writer's) unless
// the scene is too large for 24-bit integers at that precision; then fewer bits, so that any
// plausible georeferenced scene fits (with a coarser step, stated in the header).
int fractionalBitsFor(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud) {
  float extent = 0;
  for (const auto& p : cloud) {
    extent = std::max({extent, std::fabs(p.x), std::fabs(p.y), std::fabs(p.z)});
  }
  int bits = kDefaultFractionalBits;
  while (bits > 0 && extent * static_cast<float>(1 << bits) >= 8388607.0f) --bits;
  if (extent >= 8388607.0f) {
    throw Error(path, "positions", "coordinates within +-8388607 (24-bit fixed point)",
                std::to_string(extent));
  }
  return bits;
}

void packRotation(const std::array<float, 4>& u, std::size_t bytes, std::uint8_t* out) {
  if (bytes == 3) {  // version 2: x y z of the quaternion with w >= 0; w is derived on reading
    const float sign = u[0] < 0 ? -1.0f : 1.0f;
    for (int k = 0; k < 3; ++k) out[k] = toByte(127.5f + 127.5f * sign * u[1 + k]);
    return;
  }
  // Versions 3, 4: SPZ's order (x, y, z, w); the index of the largest component in the top two
  // bits, the other three as sign + 9-bit magnitude in units of 1/sqrt(2) (the largest is made
  // positive, so its sign needs no bit); the last component ends in the low bits.
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
  for (int b = 0; b < 4; ++b) out[b] = (comp >> (8 * b)) & 0xff;
}

void unpackRotation(const std::uint8_t* in, std::size_t bytes, float rot[4]) {
  if (bytes == 3) {
    float xyz[3], norm2 = 0;
    for (int k = 0; k < 3; ++k) {
      xyz[k] = in[k] / 127.5f - 1.0f;
      norm2 += xyz[k] * xyz[k];
    }
    rot[0] = std::sqrt(std::max(0.0f, 1.0f - norm2));
    for (int k = 0; k < 3; ++k) rot[1 + k] = xyz[k];
    return;
  }
  std::uint32_t comp = in[0] | (in[1] << 8) | (in[2] << 16) | (static_cast<std::uint32_t>(in[3]) << 24);
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
  rot[0] = q[3];
  rot[1] = q[0];
  rot[2] = q[1];
  rot[3] = q[2];
}

// Fills the attribute arrays of `layout` (one buffer, in file order) from the cloud, in RUB axes.
std::vector<std::uint8_t> pack(const pcl::PointCloud<GaussianPoint>& cloud, const Layout& layout,
                               int bits) {
  const std::size_t n = layout.n;
  const int rest = static_cast<int>(shDim(layout.degree));
  std::vector<std::uint8_t> data(layout.total());
  std::uint8_t* positions = data.data();
  std::uint8_t* alphas = positions + layout.positions();
  std::uint8_t* colors = alphas + layout.alphas();
  std::uint8_t* scales = colors + layout.colors();
  std::uint8_t* rotations = scales + layout.scales();
  std::uint8_t* sh = rotations + layout.rotations();
  const float fixed = static_cast<float>(1 << bits);
  for (std::size_t i = 0; i < n; ++i) {
    const GaussianPoint& p = cloud[i];
    const float xyz[3] = {p.x, -p.y, -p.z};  // RDF -> RUB
    for (int k = 0; k < 3; ++k) {
      const std::int32_t v = static_cast<std::int32_t>(std::lround(xyz[k] * fixed));
      for (int b = 0; b < 3; ++b) positions[9 * i + 3 * k + b] = (v >> (8 * b)) & 0xff;
    }
    alphas[i] = toByte(255.0f * sigmoid(p.opacity));
    for (int c = 0; c < 3; ++c) {
      colors[3 * i + c] = toByte(127.5f + kColorScale * 255.0f * p.f_dc[c]);
      scales[3 * i + c] = toByte((p.scale[c] + 10.0f) * 16.0f);
    }
    auto u = unitQuaternion(p);
    u[2] = -u[2];  // the rotation conjugated by the 180-degree turn about x: (w, x, -y, -z)
    u[3] = -u[3];
    packRotation(u, layout.rotation, rotations + layout.rotation * i);
    for (int k = 0; k < rest; ++k) {
      // Fewer significant bits for higher degrees (buckets of 8 and 16), as SPZ's own writer.
      const int bucket = k < 3 ? 8 : 16;
      for (int c = 0; c < 3; ++c) {
        const float value = kRdfRubShSign[k] * p.f_rest[c * kShRestPerChannel + k];
        int v = static_cast<int>(std::round(value * 128.0f)) + 128;
        v = (v + bucket / 2) / bucket * bucket;
        sh[(i * rest + k) * 3 + c] = static_cast<std::uint8_t>(std::clamp(v, 0, 255));
      }
    }
  }
  return data;
}

// Reads the attribute arrays of `layout` (one buffer, in file order) into a cloud in RDF axes.
pcl::PointCloud<GaussianPoint> unpack(const std::uint8_t* data, const Layout& layout, int bits) {
  const std::size_t n = layout.n;
  const std::size_t rest = shDim(layout.degree);
  const std::size_t kept = std::min<std::size_t>(rest, kShRestPerChannel);  // degree 4 dropped
  const std::uint8_t* positions = data;
  const std::uint8_t* alphas = positions + layout.positions();
  const std::uint8_t* colors = alphas + layout.alphas();
  const std::uint8_t* scales = colors + layout.colors();
  const std::uint8_t* rotations = scales + layout.scales();
  const std::uint8_t* sh = rotations + layout.rotations();
  const float fixed = static_cast<float>(std::uint32_t{1} << bits);
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
    p.y = -xyz[1];  // RUB -> RDF
    p.z = -xyz[2];
    p.opacity = logitOfAlpha(alphas[i] / 255.0f);
    for (int c = 0; c < 3; ++c) {
      p.f_dc[c] = (colors[3 * i + c] - 127.5f) / (kColorScale * 255.0f);
      p.scale[c] = scales[3 * i + c] / 16.0f - 10.0f;
    }
    unpackRotation(rotations + layout.rotation * i, layout.rotation, p.rot);
    p.rot[2] = -p.rot[2];
    p.rot[3] = -p.rot[3];
    for (std::size_t k = 0; k < kept; ++k) {
      for (int c = 0; c < 3; ++c) {
        p.f_rest[c * kShRestPerChannel + k] =
            kRdfRubShSign[k] * (sh[(i * rest + k) * 3 + c] - 128.0f) / 128.0f;
      }
    }
  }
  finishCloud(cloud);
  return cloud;
}

template <typename T>
T load(const std::uint8_t* p) {
  T v;
  std::memcpy(&v, p, sizeof(T));
  return v;
}

template <typename T>
void store(std::uint8_t* p, T v) {
  std::memcpy(p, &v, sizeof(T));
}

void checkHeader(const std::string& path, std::uint64_t n, int degree, int bits) {
  if (n > kMaxPoints) throw Error(path, "numPoints", "at most 2^28", std::to_string(n));
  if (degree > 4) throw Error(path, "shDegree", "0..4", std::to_string(degree));
  if (bits > 23) throw Error(path, "fractionalBits", "0..23", std::to_string(bits));
}

pcl::PointCloud<GaussianPoint> readLegacy(const std::string& path, const std::string& bytes,
                                          SpzFileInfo* info) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  // The header comes out first; from then on its count bounds the output (a 2 MB file that
  // claims 40 Gaussians stops after 16 + 40 records' bytes, not after gigabytes).
  const std::vector<std::uint8_t> raw = compression::gunzip(
      path, data, bytes.size(), [&](const std::vector<std::uint8_t>& out) -> std::size_t {
        if (out.size() < kLegacyHeaderBytes) return kLegacyHeaderBytes + 65536;
        const auto n = load<std::uint32_t>(out.data() + 8);
        const int degree = out[12];
        checkHeader(path, n, std::min(degree, 5), 0);
        Layout l;
        l.n = n;
        l.degree = std::min(degree, 4);
        l.rotation = 4;
        return kLegacyHeaderBytes + l.total();
      });
  if (raw.size() < kLegacyHeaderBytes) {
    throw Error(path, "header", "16 bytes", std::to_string(raw.size()) + " bytes");
  }
  if (load<std::uint32_t>(raw.data()) != kMagic) {
    throw Error(path, "magic", "0x5053474e (\"NGSP\")", "another value");
  }
  const auto version = load<std::uint32_t>(raw.data() + 4);
  if (version != 2 && version != 3) {
    throw Error(path, "version", "2 or 3 in a gzip .spz (4 is not gzip-compressed)",
                std::to_string(version));
  }
  Layout layout;
  layout.n = load<std::uint32_t>(raw.data() + 8);
  layout.degree = raw[12];
  const int bits = raw[13];
  checkHeader(path, layout.n, layout.degree, bits);
  layout.rotation = version == 3 ? 4 : 3;
  if (raw.size() != kLegacyHeaderBytes + layout.total()) {
    throw Error(path, "data",
                std::to_string(kLegacyHeaderBytes + layout.total()) + " bytes for " +
                    std::to_string(layout.n) + " Gaussians of SH degree " +
                    std::to_string(layout.degree),
                std::to_string(raw.size()));
  }
  if (info != nullptr) {
    info->version = static_cast<int>(version);
    info->sh_degree = layout.degree;
    info->fractional_bits = bits;
    info->antialiased = (raw[14] & kFlagAntialiased) != 0;
    info->extensions = false;
  }
  return unpack(raw.data() + kLegacyHeaderBytes, layout, bits);
}

pcl::PointCloud<GaussianPoint> readVersion4(const std::string& path, const std::string& bytes,
                                            SpzFileInfo* info) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  if (bytes.size() < kV4HeaderBytes) {
    throw Error(path, "header", "32 bytes (SPZ version 4)", std::to_string(bytes.size()));
  }
  const auto version = load<std::uint32_t>(data + 4);
  if (version != 4) throw Error(path, "version", "4 in an uncompressed NGSP header",
                                std::to_string(version));
  Layout layout;
  layout.n = load<std::uint32_t>(data + 8);
  layout.degree = data[12];
  const int bits = data[13];
  const std::uint8_t flags = data[14];
  const std::size_t num_streams = data[15];
  const auto toc = load<std::uint32_t>(data + 16);
  checkHeader(path, layout.n, layout.degree, bits);
  if (layout.n > bytes.size() * kMaxZstdRatio / 9) {
    throw Error(path, "numPoints",
                "at most " + std::to_string(bytes.size() * kMaxZstdRatio / 9) +
                    " for a file of " + std::to_string(bytes.size()) + " bytes",
                std::to_string(layout.n));
  }
  const std::vector<std::size_t> sizes = layout.streams();
  if (num_streams != sizes.size()) {
    throw Error(path, "numStreams",
                std::to_string(sizes.size()) + " for SH degree " + std::to_string(layout.degree),
                std::to_string(num_streams));
  }
  if (toc < kV4HeaderBytes || toc + 16 * num_streams > bytes.size()) {
    throw Error(path, "tocByteOffset",
                "32 or more, with the table of contents inside the file", std::to_string(toc));
  }
  std::vector<std::uint8_t> raw(layout.total());
  std::size_t in = toc + 16 * num_streams, out = 0;
  for (std::size_t s = 0; s < num_streams; ++s) {
    const auto compressed = load<std::uint64_t>(data + toc + 16 * s);
    const auto uncompressed = load<std::uint64_t>(data + toc + 16 * s + 8);
    const std::string field = "stream " + std::to_string(s);
    if (uncompressed != sizes[s]) {
      throw Error(path, field + " uncompressed size", std::to_string(sizes[s]) + " bytes",
                  std::to_string(uncompressed));
    }
    if (compressed > bytes.size() - in) {
      throw Error(path, field + " compressed size",
                  "at most the " + std::to_string(bytes.size() - in) + " bytes left",
                  std::to_string(compressed));
    }
    compression::zstdDecompress(path, field, data + in, compressed, raw.data() + out, sizes[s]);
    in += compressed;
    out += sizes[s];
  }
  if (in != bytes.size()) {
    throw Error(path, "size", std::to_string(in) + " bytes (header, table and streams)",
                std::to_string(bytes.size()));
  }
  if (info != nullptr) {
    info->version = 4;
    info->sh_degree = layout.degree;
    info->fractional_bits = bits;
    info->antialiased = (flags & kFlagAntialiased) != 0;
    info->extensions = (flags & kFlagExtensions) != 0;
  }
  return unpack(raw.data(), layout, bits);
}

}  // namespace

std::vector<std::uint8_t> encodeSpz(const std::string& path,
                                    const pcl::PointCloud<GaussianPoint>& cloud,
                                    const SpzWriteOptions& options) {
  if (options.sh_degree < 0 || options.sh_degree > kMaxShDegree) {
    throw Error(path, "SH degree option", "0..3", std::to_string(options.sh_degree));
  }
  if (options.version < 2 || options.version > 4) {
    throw Error(path, "SPZ version option", "2, 3 or 4", std::to_string(options.version));
  }
  checkWritableGaussians(path, cloud);
  if (cloud.size() > kMaxPoints) {
    throw Error(path, "Gaussian count", "at most 2^28 for SPZ", std::to_string(cloud.size()));
  }
  Layout layout;
  layout.n = cloud.size();
  layout.degree = options.sh_degree;
  layout.rotation = options.version == 2 ? 3 : 4;
  const int bits = fractionalBitsFor(path, cloud);
  std::vector<std::uint8_t> data;
  if (options.axes_as_stored) {
    pcl::PointCloud<GaussianPoint> turned = cloud;
    turnAboutX(turned);
    data = pack(turned, layout, bits);
  } else {
    data = pack(cloud, layout, bits);
  }
  const std::uint8_t flags = options.antialiased ? kFlagAntialiased : 0;
  std::vector<std::uint8_t> file;
  if (options.version < 4) {
    std::vector<std::uint8_t> raw(kLegacyHeaderBytes);
    store<std::uint32_t>(raw.data(), kMagic);
    store<std::uint32_t>(raw.data() + 4, static_cast<std::uint32_t>(options.version));
    store<std::uint32_t>(raw.data() + 8, static_cast<std::uint32_t>(layout.n));
    raw[12] = static_cast<std::uint8_t>(layout.degree);
    raw[13] = static_cast<std::uint8_t>(bits);
    raw[14] = flags;
    raw.insert(raw.end(), data.begin(), data.end());
    file = compression::gzip(path, raw.data(), raw.size());
  } else {
    const std::vector<std::size_t> sizes = layout.streams();
    file.assign(kV4HeaderBytes + 16 * sizes.size(), 0);
    store<std::uint32_t>(file.data(), kMagic);
    store<std::uint32_t>(file.data() + 4, 4);
    store<std::uint32_t>(file.data() + 8, static_cast<std::uint32_t>(layout.n));
    file[12] = static_cast<std::uint8_t>(layout.degree);
    file[13] = static_cast<std::uint8_t>(bits);
    file[14] = flags;
    file[15] = static_cast<std::uint8_t>(sizes.size());
    store<std::uint32_t>(file.data() + 16, static_cast<std::uint32_t>(kV4HeaderBytes));
    std::size_t offset = 0;
    for (std::size_t s = 0; s < sizes.size(); ++s) {
      const std::vector<std::uint8_t> z =
          compression::zstdCompress(path, data.data() + offset, sizes[s]);
      store<std::uint64_t>(file.data() + kV4HeaderBytes + 16 * s, z.size());
      store<std::uint64_t>(file.data() + kV4HeaderBytes + 16 * s + 8, sizes[s]);
      file.insert(file.end(), z.begin(), z.end());
      offset += sizes[s];
    }
  }
  return file;
}

void writeSpz(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
              const SpzWriteOptions& options) {
  const std::vector<std::uint8_t> file = encodeSpz(path, cloud, options);
  writeFileAtomically(path, [&](std::ostream& out) {
    out.write(reinterpret_cast<const char*>(file.data()), static_cast<std::streamsize>(file.size()));
  });
}

pcl::PointCloud<GaussianPoint> readSpz(const std::string& path, SpzFileInfo* info) {
  return decodeSpz(path, readWholeFile(path), info);
}

pcl::PointCloud<GaussianPoint> decodeSpz(const std::string& path, const std::string& bytes,
                                         SpzFileInfo* info, bool axes_as_stored) {
  const auto* data = reinterpret_cast<const std::uint8_t*>(bytes.data());
  pcl::PointCloud<GaussianPoint> cloud;
  if (bytes.size() >= 4 && load<std::uint32_t>(data) == kMagic) {
    cloud = readVersion4(path, bytes, info);
  } else if (bytes.size() >= 18 && data[0] == 0x1f && data[1] == 0x8b) {
    cloud = readLegacy(path, bytes, info);
  } else {
    throw Error(path, "header",
                "an .spz file: \"NGSP\" (version 4) or gzip data starting 1f 8b (versions 2, 3)",
                bytes.size() < 4 ? "a file of " + std::to_string(bytes.size()) + " bytes"
                                 : "other bytes");
  }
  if (axes_as_stored) turnAboutX(cloud);
  const GaussianReadReport report = checkReadGaussians(path, cloud);
  if (info != nullptr) {
    info->num_points = cloud.size();
    info->clamped_opacities = report.clamped_opacities;
  }
  return cloud;
}

}  // namespace io
}  // namespace sadsplat
