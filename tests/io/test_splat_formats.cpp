// .splat and .spz: round trips within the quantisation the formats state, and bad files.
#include <gtest/gtest.h>

#include <zlib.h>

#include <chrono>
#include <cmath>
#include <cstring>

#include "sadsplat/common/error.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/splat_formats.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

float sigmoid(float x) { return 1.0f / (1.0f + std::exp(-x)); }

// Random Gaussians in the ranges real models have (the test helper's values are arbitrary).
pcl::PointCloud<GaussianPoint> plausibleGaussians(std::size_t n) {
  auto cloud = test::randomGaussians(n, 77);
  std::uint64_t state = 12345;
  const auto uniform = [&](float lo, float hi) {
    state = state * 6364136223846793005ull + 1442695040888963407ull;
    return lo + (hi - lo) * static_cast<float>((state >> 40) & 0xffffff) / 16777216.0f;
  };
  for (auto& p : cloud) {
    p.x = uniform(-50, 50);
    p.y = uniform(-50, 50);
    p.z = uniform(-5, 20);
    for (float& s : p.scale) s = uniform(-7, 1);
    p.opacity = uniform(-5, 5);
    for (float& c : p.f_dc) c = uniform(-1.7f, 1.7f);
    for (float& c : p.f_rest) c = uniform(-0.9f, 0.9f);
    for (float& r : p.rot) r = uniform(-1, 1);
  }
  return cloud;
}

std::array<float, 4> unit(const float* q) {
  const float n = std::sqrt(q[0] * q[0] + q[1] * q[1] + q[2] * q[2] + q[3] * q[3]);
  std::array<float, 4> u{q[0] / n, q[1] / n, q[2] / n, q[3] / n};
  if (u[0] < 0) {
    for (float& v : u) v = -v;
  }
  return u;
}

TEST(SplatFormats, SplatRoundTripWithinItsQuantisation) {
  test::TempDir dir;
  const auto cloud = plausibleGaussians(300);
  io::writeSplat(dir.file("m.splat"), cloud);
  EXPECT_EQ(test::readFile(dir.file("m.splat")).size(), 300u * 32);
  const auto back = io::readGaussians(dir.file("m.splat"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto &a = cloud[i], &b = back[i];
    EXPECT_EQ(a.x, b.x);
    EXPECT_EQ(a.z, b.z);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a.scale[k], b.scale[k], 1e-5);
      const float ca = std::clamp(0.5f + 0.28209479f * a.f_dc[k], 0.0f, 1.0f);
      EXPECT_NEAR(ca, 0.5f + 0.28209479f * b.f_dc[k], 0.5f / 255 + 1e-6);
    }
    EXPECT_NEAR(sigmoid(a.opacity), sigmoid(b.opacity), 0.5f / 255 + 1e-6);
    const auto qa = unit(a.rot), qb = unit(b.rot);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.5f / 128 + 1e-3) << i;
    EXPECT_EQ(b.label, kUnlabelled);
  }
}

// Every attribute of `b` (read back from SPZ) within the format's quantisation of `a`.
void expectWithinSpzQuantisation(const pcl::PointCloud<GaussianPoint>& a,
                                 const pcl::PointCloud<GaussianPoint>& b, double position_step) {
  ASSERT_EQ(a.size(), b.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const auto &p = a[i], &q = b[i];
    EXPECT_NEAR(p.x, q.x, position_step / 2 + 1e-5) << i;
    EXPECT_NEAR(p.y, q.y, position_step / 2 + 1e-5) << i;
    EXPECT_NEAR(p.z, q.z, position_step / 2 + 1e-5) << i;
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(p.scale[k], q.scale[k], 1.0 / 32 + 1e-5);
      EXPECT_NEAR(p.f_dc[k], q.f_dc[k], 0.5 / (0.15 * 255) + 1e-5);
    }
    EXPECT_NEAR(sigmoid(p.opacity), sigmoid(q.opacity), 0.5 / 255 + 1e-5);
    const auto qa = unit(p.rot), qb = unit(q.rot);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.002) << i << " " << k;
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 15; ++k) {
        const float tolerance = k < 3 ? 4.5f / 128 : 8.5f / 128;
        EXPECT_NEAR(p.f_rest[c * 15 + k], q.f_rest[c * 15 + k], tolerance) << c << " " << k;
      }
    }
  }
}

TEST(SplatFormats, SpzRoundTripWithinItsQuantisation) {
  test::TempDir dir;
  const auto cloud = plausibleGaussians(300);
  io::writeGaussians(dir.file("m.spz"), cloud);
  io::SpzFileInfo info;
  const auto back = io::readSpz(dir.file("m.spz"), &info);
  EXPECT_EQ(info.version, 3);
  EXPECT_EQ(info.sh_degree, 3);
  EXPECT_EQ(info.fractional_bits, 12);
  EXPECT_FALSE(info.antialiased);
  expectWithinSpzQuantisation(cloud, back, 1.0 / 4096);
  // Compact: well under a third of the float PLY's 248 bytes per Gaussian.
  EXPECT_LT(test::readFile(dir.file("m.spz")).size(), 300u * 80);
}

TEST(SplatFormats, SpzVersion4RoundTripKeepsTheAntialiasingFlag) {
  test::TempDir dir;
  const auto cloud = plausibleGaussians(300);
  io::SpzWriteOptions options;
  options.version = 4;
  options.antialiased = true;
  io::writeSpz(dir.file("v4.spz"), cloud, options);
  EXPECT_EQ(test::readFile(dir.file("v4.spz")).substr(0, 4), "NGSP");  // plain header
  io::SpzFileInfo info;
  const auto back = io::readSpz(dir.file("v4.spz"), &info);
  EXPECT_EQ(info.version, 4);
  EXPECT_TRUE(info.antialiased);
  expectWithinSpzQuantisation(cloud, back, 1.0 / 4096);
  // Degree 0: no SH stream at all (five streams).
  options.sh_degree = 0;
  io::writeSpz(dir.file("v4_sh0.spz"), cloud, options);
  EXPECT_EQ(test::readFile(dir.file("v4_sh0.spz"))[15], 5);
  EXPECT_EQ(io::readSpz(dir.file("v4_sh0.spz"))[7].f_rest[0], 0.0f);
}

// Scenes beyond +-2048 (georeferenced metres) keep fewer fractional bits instead of failing.
TEST(SplatFormats, SpzLargeScenesUseACoarserPositionStep) {
  test::TempDir dir;
  auto cloud = plausibleGaussians(20);
  cloud[0].x = 5000;
  cloud[1].z = -7000;
  io::writeSpz(dir.file("far.spz"), cloud);
  io::SpzFileInfo info;
  const auto back = io::readSpz(dir.file("far.spz"), &info);
  EXPECT_EQ(info.fractional_bits, 10);  // 7000 * 2^10 < 2^23 <= 7000 * 2^11
  expectWithinSpzQuantisation(cloud, back, 1.0 / 1024);
}

// Files written by PlayCanvas' splat-transform 2.7.1 from data/interop/gaussians_sh3.ply (the
// official SPZ encoder compiled to WASM, RDF in, RUB on disk): sadsplat reads the PLY's values
// back within the format's quantisation, so both sides agree on the axes.
TEST(SplatFormats, ReadsSplatTransformSpzVersions3And4) {
  const std::string dir = std::string(SADSPLAT_TEST_DATA_DIR) + "/interop/";
  const auto source = io::readGaussianPly(dir + "gaussians_sh3.ply");
  for (const char* name : {"splat_transform_v3.spz", "splat_transform_v4.spz"}) {
    SCOPED_TRACE(name);
    io::SpzFileInfo info;
    const auto cloud = io::readSpz(dir + name, &info);
    EXPECT_EQ(info.sh_degree, 3);
    expectWithinSpzQuantisation(source, cloud, 1.0 / 4096);
  }
}

// splat-transform's SOG and compressed PLY reorder the Gaussians (Morton order); its own decode
// of each file (splat-transform X out.ply) is the reference sadsplat's reader must match.
TEST(SplatFormats, ReadsSplatTransformSogAndCompressedPlyAsItsOwnDecoder) {
  const std::string dir = std::string(SADSPLAT_TEST_DATA_DIR) + "/interop/";
  const std::pair<const char*, const char*> cases[] = {
      {"splat_transform.sog", "splat_transform_sog_decoded.ply"},
      {"splat_transform.compressed.ply", "splat_transform_compressed_decoded.ply"}};
  for (const auto& [file, decoded] : cases) {
    SCOPED_TRACE(file);
    if (std::string(file).find(".sog") != std::string::npos && !io::haveSogSupport()) continue;
    const auto ours = io::readGaussians(dir + file);
    // The reference decode keeps 255 alphas as +inf: readGaussianPly clamps them as counted.
    io::PlyFileInfo info;
    const auto reference = io::readGaussianPly(dir + decoded, &info);
    ASSERT_EQ(ours.size(), reference.size());
    std::size_t opaque = 0;
    for (std::size_t i = 0; i < ours.size(); ++i) {
      const auto &a = ours[i], &b = reference[i];
      for (float d : {a.x - b.x, a.y - b.y, a.z - b.z}) EXPECT_NEAR(d, 0.0f, 1e-4f) << i;
      for (int k = 0; k < 3; ++k) {
        EXPECT_NEAR(a.scale[k], b.scale[k], 1e-4f) << i;
        EXPECT_NEAR(a.f_dc[k], b.f_dc[k], 1e-4f) << i;
      }
      for (int k = 0; k < 4; ++k) EXPECT_NEAR(a.rot[k], b.rot[k], 1e-4f) << i;
      for (int k = 0; k < 45; ++k) EXPECT_NEAR(a.f_rest[k], b.f_rest[k], 1e-4f) << i << " " << k;
      // Opacity: equal where the alpha is inside (0, 1); 0 and 1 are finite logits here.
      if (std::fabs(b.opacity) < io::kMaxOpacityLogit) {
        EXPECT_NEAR(a.opacity, b.opacity, 1e-3f) << i;
      } else {
        ++opaque;
        EXPECT_GT(sigmoid(a.opacity) * sigmoid(b.opacity), 0.99f) << i;
      }
    }
    EXPECT_EQ(opaque, info.clamped_opacities);
  }
}

// Version 2 (for older viewers): the same except the quaternion, whose w is derived from x y z.
TEST(SplatFormats, SogRoundTripWithinItsQuantisation) {
  if (!io::haveSogSupport()) GTEST_SKIP() << "built without libwebp";
  test::TempDir dir;
  const auto cloud = plausibleGaussians(500);
  io::writeGaussians(dir.file("m.sog"), cloud);
  io::SogFileInfo info;
  const auto back = io::readSog(dir.file("m.sog"), &info);
  ASSERT_EQ(back.size(), cloud.size());
  EXPECT_EQ(info.sh_bands, 3);
  double position = 0, scale = 0, colour = 0, alpha = 0, sh = 0, rotation = 0;
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto& a = cloud[i];
    const auto& b = back[i];
    // 16 bits of log(1 + |x|) over [-log 51, log 51]: a step of ~1.2e-4 in log space.
    const float xyz_a[3] = {a.x, a.y, a.z}, xyz_b[3] = {b.x, b.y, b.z};
    for (int k = 0; k < 3; ++k) {
      position = std::max(position, double(std::fabs(xyz_a[k] - xyz_b[k]) / (1 + std::fabs(xyz_a[k]))));
    }
    for (int k = 0; k < 3; ++k) {
      scale = std::max(scale, double(std::fabs(a.scale[k] - b.scale[k])));
      colour = std::max(colour, double(std::fabs(a.f_dc[k] - b.f_dc[k])));
    }
    alpha = std::max(alpha, std::fabs(1 / (1 + std::exp(-double(a.opacity))) -
                                      1 / (1 + std::exp(-double(b.opacity)))));
    for (int k = 0; k < 45; ++k) sh = std::max(sh, double(std::fabs(a.f_rest[k] - b.f_rest[k])));
    const auto qa = unit(a.rot), qb = unit(b.rot);
    double dot = 0;
    for (int k = 0; k < 4; ++k) dot += qa[k] * qb[k];
    rotation = std::max(rotation, 1 - std::fabs(dot));
  }
  EXPECT_LT(position, 1.5e-4);
  EXPECT_LT(scale, 0.05);   // 256 entries over [-7, 1]: half a gap of ~0.03
  EXPECT_LT(colour, 0.02);  // over [-1.7, 1.7]
  EXPECT_LT(alpha, 0.5 / 255 + 1e-4);
  EXPECT_LT(sh, 0.01);      // over [-0.9, 0.9]
  EXPECT_LT(rotation, 2e-4);
  // Smaller than the .spz of the same model would not be a fair bound (no gzip); the float PLY's
  // 248 bytes per Gaussian is.
  EXPECT_LT(test::readFile(dir.file("m.sog")).size(), 500u * 120);
}

TEST(SplatFormats, SpzVersion2ReadsBack) {
  test::TempDir dir;
  auto cloud = plausibleGaussians(100);
  for (auto& p : cloud) p.rot[0] = std::max(std::fabs(p.rot[0]), 0.8f);  // w well away from 0
  io::SpzWriteOptions v2;
  v2.version = 2;
  io::writeSpz(dir.file("v2.spz"), cloud, v2);
  const auto back = io::readSpz(dir.file("v2.spz"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto qa = unit(cloud[i].rot), qb = unit(back[i].rot);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.02) << i;
    EXPECT_NEAR(cloud[i].x, back[i].x, 0.5 / 4096 + 1e-5);
  }
  io::SpzWriteOptions v5;
  v5.version = 5;
  EXPECT_THROW(io::writeSpz(dir.file("v5.spz"), cloud, v5), Error);
}

TEST(SplatFormats, BadFilesAreErrors) {
  test::TempDir dir;
  test::writeFile(dir.file("odd.splat"), std::string(33, '\0'));
  EXPECT_THROW(io::readSplat(dir.file("odd.splat")), Error);
  test::writeFile(dir.file("plain.spz"), "not gzip at all, just text");
  EXPECT_THROW(io::readSpz(dir.file("plain.spz")), Error);
  io::writeSpz(dir.file("ok.spz"), plausibleGaussians(50));
  const std::string ok = test::readFile(dir.file("ok.spz"));
  test::writeFile(dir.file("cut.spz"), ok.substr(0, ok.size() / 2));
  try {
    io::readSpz(dir.file("cut.spz"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "gzip data");
  }
  std::string flipped = ok;
  for (std::size_t k = 20; k < 40; ++k) flipped[k] = static_cast<char>(~flipped[k]);
  test::writeFile(dir.file("flipped.spz"), flipped);
  EXPECT_THROW(io::readSpz(dir.file("flipped.spz")), Error);
  auto nan = plausibleGaussians(2);
  nan[1].x = std::nanf("");
  EXPECT_THROW(io::writeSplat(dir.file("nan.splat"), nan), Error);
  auto far = plausibleGaussians(2);
  far[0].x = 2e7f;  // beyond the plausible range (gaussian_checks.h)
  EXPECT_THROW(io::writeSpz(dir.file("far.spz"), far), Error);
  test::writeFile(dir.file("empty.splat"), "");
  EXPECT_THROW(io::readSplat(dir.file("empty.splat")), Error);
}

std::string gzipBytes(const std::string& data) {
  z_stream s{};
  deflateInit2(&s, 9, Z_DEFLATED, 16 + MAX_WBITS, 9, Z_DEFAULT_STRATEGY);
  std::string out(deflateBound(&s, data.size()) + 64, '\0');
  s.next_in = reinterpret_cast<Bytef*>(const_cast<char*>(data.data()));
  s.avail_in = static_cast<uInt>(data.size());
  s.next_out = reinterpret_cast<Bytef*>(out.data());
  s.avail_out = static_cast<uInt>(out.size());
  deflate(&s, Z_FINISH);
  out.resize(out.size() - s.avail_out);
  deflateEnd(&s);
  return out;
}

// A compression bomb: a header that claims 40 Gaussians followed by 64 MB of zeros (64 kB of
// gzip). Inflation stops at what 40 Gaussians need instead of producing everything first.
TEST(SplatFormats, SpzInflationIsBoundedByTheHeadersCount) {
  test::TempDir dir;
  std::string raw(16, '\0');
  const std::uint32_t header[3] = {0x5053474e, 3, 40};
  std::memcpy(raw.data(), header, 12);
  raw[12] = 3;
  raw[13] = 12;
  raw.append(std::size_t{64} << 20, '\0');
  test::writeFile(dir.file("bomb.spz"), gzipBytes(raw));
  const auto start = std::chrono::steady_clock::now();
  try {
    io::readSpz(dir.file("bomb.spz"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "gzip data");
    EXPECT_NE(std::string(e.what()).find("at most 2616 bytes"), std::string::npos) << e.what();
  }
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2.0);
  // Version 1 (float16 positions) is refused by name.
  std::string v1(16 + 40 * 20, '\0');
  const std::uint32_t header1[3] = {0x5053474e, 1, 40};
  std::memcpy(v1.data(), header1, 12);
  test::writeFile(dir.file("v1.spz"), gzipBytes(v1));
  try {
    io::readSpz(dir.file("v1.spz"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "version");
  }
}

}  // namespace
}  // namespace sadsplat
