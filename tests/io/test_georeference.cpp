// The georeference: WGS84 <-> east-north-up, UTM zones, the robust similarity fit, EXIF GPS
// written by sadsplat and read back through libexif, and the JSON and cache round trips.
#include <gtest/gtest.h>

#include <cmath>
#include <fstream>
#include <random>

#include "sadsplat/common/error.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/scene_cache.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(Georeference, EastNorthUpIsMetresAroundTheOrigin) {
  const io::GeoPosition origin{46.843, -91.994, 198.6};
  // One arc-second of latitude is ~30.9 m here; 0.001 degree of longitude ~76 m at 46.8 N.
  const auto north = io::toEnu({origin.latitude + 1.0 / 3600, origin.longitude, 198.6}, origin);
  EXPECT_NEAR(north[0], 0.0, 1e-6);
  EXPECT_NEAR(north[1], 30.88, 0.05);
  EXPECT_NEAR(north[2], 0.0, 1e-3);  // the ellipsoid's curvature over 31 m: < 0.1 mm
  const auto east = io::toEnu({origin.latitude, origin.longitude + 0.001, 198.6}, origin);
  EXPECT_NEAR(east[0], 111320 * std::cos(origin.latitude * M_PI / 180) * 0.001, 0.3);
  EXPECT_NEAR(east[1], 0.0, 0.01);
  const auto up = io::toEnu({origin.latitude, origin.longitude, 298.6}, origin);
  EXPECT_NEAR(up[2], 100.0, 1e-6);
  // The inverse, to a millimetre.
  const io::GeoPosition back = io::fromEnu({123.4, -567.8, 42.0}, origin);
  const auto again = io::toEnu(back, origin);
  EXPECT_NEAR(again[0], 123.4, 1e-3);
  EXPECT_NEAR(again[1], -567.8, 1e-3);
  EXPECT_NEAR(again[2], 42.0, 1e-3);
}

TEST(Georeference, UtmZoneEpsgCodes) {
  EXPECT_EQ(io::utmEpsg({46.843, -91.994, 0}), 32615);  // Duluth, MN: zone 15 N
  EXPECT_EQ(io::utmEpsg({48.137, 11.575, 0}), 32632);   // Munich: zone 32 N
  EXPECT_EQ(io::utmEpsg({-33.87, 151.21, 0}), 32756);   // Sydney: zone 56 S
  EXPECT_EQ(io::utmEpsg({0.0, -180.0, 0}), 32601);
  EXPECT_EQ(io::utmEpsg({0.0, 180.0, 0}), 32660);
}

TEST(Georeference, SimilarityFitRecoversScaleRotationAndTranslationDespiteOutliers) {
  io::Similarity truth;
  truth.scale = 37.5;
  const double a = 0.7, c = std::cos(a), s = std::sin(a);
  // A rotation about z, then a tilt about x (an SfM frame is arbitrary).
  const double t = 0.3, ct = std::cos(t), st = std::sin(t);
  truth.rotation = {c, -s * ct, s * st, s, c * ct, -c * st, 0, st, ct};
  truth.translation = {100, -50, 20};
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.5);  // GPS noise, metres
  std::uniform_real_distribution<double> where(-2, 2);
  std::vector<std::array<double, 3>> from, to;
  for (int i = 0; i < 30; ++i) {
    const std::array<double, 3> x{where(rng), where(rng), 0.1 * where(rng)};
    auto y = truth.apply(x);
    for (auto& v : y) v += noise(rng);
    if (i % 10 == 3) y[2] += 80;  // three photos with a wild GPS altitude
    from.push_back(x);
    to.push_back(y);
  }
  std::vector<bool> inliers;
  bool consensus = false;
  const io::Similarity fit = io::fitSimilarity(from, to, 3.0, &inliers, &consensus);
  EXPECT_TRUE(consensus);
  EXPECT_NEAR(fit.scale, truth.scale, 0.02 * truth.scale);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(fit.rotation[k], truth.rotation[k], 0.02) << k;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(fit.translation[k], truth.translation[k], 1.0) << k;
  int outliers_found = 0;
  for (int i = 0; i < 30; ++i) outliers_found += (i % 10 == 3) && !inliers[i];
  EXPECT_EQ(outliers_found, 3);
  EXPECT_EQ(std::count(inliers.begin(), inliers.end(), true), 27);
  // Too few or degenerate pairs are errors, not a NaN transform.
  EXPECT_THROW(io::fitSimilarity({from[0], from[1]}, {to[0], to[1]}, 3.0), Error);
  EXPECT_THROW(io::fitSimilarity({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}},
                                 {{0, 0, 0}, {2, 0, 0}, {4, 0, 0}, {6, 0, 0}}, 3.0),
               Error);
}

// A reconstruction that does not match the flight (seen on a real 6-photo survey: two strips
// joined wrongly, camera centres 20-110 m from their GPS): no 3 pairs agree within the distance.
// The fit of all pairs comes back flagged, and only pairs really within the distance under it
// count as inliers (they were all reported as inliers before).
TEST(Georeference, WithoutConsensusTheFitOfAllIsFlaggedAndInliersAreHonest) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 40);  // metres: a reconstruction that is wrong
  std::vector<std::array<double, 3>> from, to;
  for (int i = 0; i < 6; ++i) {
    const std::array<double, 3> x{10.0 * (i % 3), 20.0 * (i / 3), 0.0};
    from.push_back(x);
    to.push_back({x[0] + noise(rng), x[1] + noise(rng), x[2] + noise(rng)});
  }
  std::vector<bool> inliers;
  bool consensus = true;
  const io::Similarity fit = io::fitSimilarity(from, to, 1.0, &inliers, &consensus);
  EXPECT_FALSE(consensus);
  int within = 0;
  for (int i = 0; i < 6; ++i) {
    const auto y = fit.apply(from[i]);
    const double d = std::hypot(y[0] - to[i][0], y[1] - to[i][1], y[2] - to[i][2]);
    EXPECT_EQ(static_cast<bool>(inliers[i]), d <= 1.0) << i << ": " << d << " m";
    within += d <= 1.0;
  }
  EXPECT_LT(within, 3);
  for (double v : fit.rotation) EXPECT_TRUE(std::isfinite(v));
}

TEST(Georeference, ExifGpsWrittenBySadsplatIsReadBackByLibexif) {
  if (!io::haveExif()) GTEST_SKIP() << "built without libexif";
  test::TempDir tmp;
  // The smallest JPEG stream that libexif accepts: SOI, our APP1, EOI.
  const std::vector<unsigned char> bare = {0xFF, 0xD8, 0xFF, 0xD9};
  const io::GeoPosition where{-33.8712345, 151.2098765, 123.456};
  const auto bytes = io::jpegWithExifGps(bare, where);
  const std::string path = tmp.file("photo.jpg");
  std::ofstream(path, std::ios::binary)
      .write(reinterpret_cast<const char*>(bytes.data()),
             static_cast<std::streamsize>(bytes.size()));
  const auto read = io::readExifGps(path);
  ASSERT_TRUE(read.has_value());
  EXPECT_NEAR(read->latitude, where.latitude, 1e-9);
  EXPECT_NEAR(read->longitude, where.longitude, 1e-9);
  EXPECT_NEAR(read->altitude, where.altitude, 1e-3);
  // With an Exif IFD for the focal length (before the GPS IFD) the GPS still reads back.
  const auto with_focal = io::jpegWithExifGps(bare, where, 31);
  test::writeFile(path, std::string(with_focal.begin(), with_focal.end()));
  const auto again = io::readExifGps(path);
  ASSERT_TRUE(again.has_value());
  EXPECT_NEAR(again->latitude, where.latitude, 1e-9);
  EXPECT_NEAR(again->altitude, where.altitude, 1e-3);
  // A photo without EXIF has no position; a non-JPEG is refused by the writer.
  const std::string plain = tmp.file("plain.jpg");
  std::ofstream(plain, std::ios::binary).write("\xFF\xD8\xFF\xD9", 4);
  EXPECT_FALSE(io::readExifGps(plain).has_value());
  EXPECT_THROW(io::jpegWithExifGps({0x89, 'P', 'N', 'G'}, where), Error);
}

TEST(Georeference, JsonAndSceneCacheRoundTrips) {
  io::Georeference g;
  g.origin = {46.843, -91.994, 198.6};
  g.epsg_utm = 32615;
  g.sfm_to_local.scale = 12.5;
  g.sfm_to_local.translation = {1, 2, 3};
  g.photos_with_gps = 18;
  g.inliers = 17;
  g.consensus = false;
  g.rms_metres = 0.8;
  const io::Georeference back = io::georeferenceFromJson(io::georeferenceToJson(g), "<test>");
  EXPECT_DOUBLE_EQ(back.origin.latitude, g.origin.latitude);
  EXPECT_EQ(back.epsg_utm, 32615);
  EXPECT_DOUBLE_EQ(back.sfm_to_local.scale, 12.5);
  EXPECT_EQ(back.inliers, 17);
  EXPECT_FALSE(back.consensus);
  // Bad files name the field.
  try {
    io::georeferenceFromJson("{\"origin\": {\"latitude\": 95, \"longitude\": 0, \"altitude\": 0}}",
                             "geo.json");
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), "geo.json");
    EXPECT_NE(std::string(e.what()).find("origin"), std::string::npos) << e.what();
  }
  EXPECT_THROW(io::georeferenceFromJson("{\"origin\": 3}", "geo.json"), Error);
  // The EPSG code must be the origin's UTM zone (Duluth: 15 N = 32615) or a neighbour.
  const auto withEpsg = [](const std::string& epsg, const std::string& altitude = "198.6") {
    return "{\"origin\": {\"latitude\": 46.843, \"longitude\": -91.994, \"altitude\": " + altitude +
           "}, \"epsg_utm\": " + epsg + "}";
  };
  EXPECT_EQ(io::georeferenceFromJson(withEpsg("32615"), "geo.json").epsg_utm, 32615);
  EXPECT_EQ(io::georeferenceFromJson(withEpsg("32616"), "geo.json").epsg_utm, 32616);
  for (const std::string bad : {"4326", "32715", "32620", "32615.5", "1e300"}) {
    try {
      io::georeferenceFromJson(withEpsg(bad), "geo.json");
      ADD_FAILURE() << bad;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find("EPSG:32615"), std::string::npos) << e.what();
    }
  }
  EXPECT_THROW(io::georeferenceFromJson(withEpsg("32615", "1e308"), "geo.json"), Error);
  // The scene cache keeps it (a chunk older readers skip); a scene without one stays without.
  test::TempDir tmp;
  io::Scene scene;
  scene.source = "geo";
  scene.georeference = g;
  io::writeSceneCache(tmp.file("geo.cache"), scene);
  const io::Scene read = io::readSceneCache(tmp.file("geo.cache"));
  ASSERT_TRUE(read.georeference.has_value());
  EXPECT_DOUBLE_EQ(read.georeference->origin.longitude, -91.994);
  EXPECT_EQ(read.georeference->photos_with_gps, 18);
  scene.georeference.reset();
  io::writeSceneCache(tmp.file("plain.cache"), scene);
  EXPECT_FALSE(io::readSceneCache(tmp.file("plain.cache")).georeference.has_value());
}

}  // namespace
}  // namespace sadsplat
