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
