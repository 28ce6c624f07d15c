// .splat and .spz: round trips within the quantisation the formats state, and bad files.
#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/io/cloud_files.h"
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

TEST(SplatFormats, SpzRoundTripWithinItsQuantisation) {
  test::TempDir dir;
  const auto cloud = plausibleGaussians(300);
  io::writeGaussians(dir.file("m.spz"), cloud);
  const auto back = io::readSpz(dir.file("m.spz"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto &a = cloud[i], &b = back[i];
    EXPECT_NEAR(a.x, b.x, 0.5 / 4096 + 1e-5);
    EXPECT_NEAR(a.y, b.y, 0.5 / 4096 + 1e-5);
    EXPECT_NEAR(a.z, b.z, 0.5 / 4096 + 1e-5);
    for (int k = 0; k < 3; ++k) {
      EXPECT_NEAR(a.scale[k], b.scale[k], 1.0 / 32 + 1e-5);
      EXPECT_NEAR(a.f_dc[k], b.f_dc[k], 0.5 / (0.15 * 255) + 1e-5);
    }
    EXPECT_NEAR(sigmoid(a.opacity), sigmoid(b.opacity), 0.5 / 255 + 1e-5);
    const auto qa = unit(a.rot), qb = unit(b.rot);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.002) << i << " " << k;
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 15; ++k) {
        const float tolerance = k < 3 ? 4.5f / 128 : 8.5f / 128;
        EXPECT_NEAR(a.f_rest[c * 15 + k], b.f_rest[c * 15 + k], tolerance) << c << " " << k;
      }
    }
  }
  // Compact: well under a third of the float PLY's 248 bytes per Gaussian.
  EXPECT_LT(test::readFile(dir.file("m.spz")).size(), 300u * 80);
}

// Version 2 (for older viewers): the same except the quaternion, whose w is derived from x y z.
TEST(SplatFormats, SpzVersion2ReadsBack) {
  test::TempDir dir;
  auto cloud = plausibleGaussians(100);
  for (auto& p : cloud) p.rot[0] = std::max(std::fabs(p.rot[0]), 0.8f);  // w well away from 0
  io::writeSpz(dir.file("v2.spz"), cloud, 3, 2);
  const auto back = io::readSpz(dir.file("v2.spz"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const auto qa = unit(cloud[i].rot), qb = unit(back[i].rot);
    for (int k = 0; k < 4; ++k) EXPECT_NEAR(qa[k], qb[k], 0.02) << i;
    EXPECT_NEAR(cloud[i].x, back[i].x, 0.5 / 4096 + 1e-5);
  }
  EXPECT_THROW(io::writeSpz(dir.file("v4.spz"), cloud, 3, 4), Error);
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
  far[0].x = 5000;
  EXPECT_THROW(io::writeSpz(dir.file("far.spz"), far), Error);
}

}  // namespace
}  // namespace sadsplat
