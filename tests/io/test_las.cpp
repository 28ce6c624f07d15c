// The LAS 1.4 writer and reader: the bytes at the specification's offsets (ASPRS LAS 1.4 R15,
// tables 3, 4 and 15), the round trip, the classification defaults, and bad files and maps.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <limits>

#include "sadsplat/common/error.h"
#include "sadsplat/io/las.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

template <typename T>
T at(const std::string& b, std::size_t offset) {
  T v;
  std::memcpy(&v, b.data() + offset, sizeof(T));
  return v;
}

std::vector<io::LasPoint> somePoints() {
  std::vector<io::LasPoint> points;
  for (int i = 0; i < 5; ++i) {
    io::LasPoint p;
    p.x = 500123.25 + 10.5 * i;
    p.y = 5187654.125 - 3.25 * i;
    p.z = 198.6 + 0.0004 * i;
    p.rgb = {std::uint16_t(257 * (10 * i)), std::uint16_t(65535 - i), std::uint16_t(i)};
    p.classification = static_cast<std::uint8_t>(i == 4 ? 66 : 2 + i);
    points.push_back(p);
  }
  return points;
}

const char* kWkt = "PROJCS[\"WGS 84 / UTM zone 15N\",AUTHORITY[\"EPSG\",\"32615\"]]";

TEST(Las, HeaderVlrAndRecordsSitAtTheSpecificationsOffsets) {
  test::TempDir dir;
  io::LasHeader h;
  h.wkt = kWkt;
  io::writeLas(dir.file("a.las"), somePoints(), h);
  const std::string b = test::readFile(dir.file("a.las"));
  const std::size_t wkt_bytes = std::strlen(kWkt) + 1;
  ASSERT_EQ(b.size(), 375 + 54 + wkt_bytes + 5 * 36);
  EXPECT_EQ(b.substr(0, 4), "LASF");
  EXPECT_EQ(at<std::uint16_t>(b, 6), 16);  // global encoding: WKT
  EXPECT_EQ(b[24], 1);
  EXPECT_EQ(b[25], 4);
  EXPECT_EQ(at<std::uint16_t>(b, 94), 375);                   // header size
  EXPECT_EQ(at<std::uint32_t>(b, 96), 375 + 54 + wkt_bytes);  // offset to point data
  EXPECT_EQ(at<std::uint32_t>(b, 100), 1u);                   // VLRs
  EXPECT_EQ(static_cast<unsigned char>(b[104]), 7);           // point data record format
  EXPECT_EQ(at<std::uint16_t>(b, 105), 36);                   // record length
  EXPECT_EQ(at<std::uint32_t>(b, 107), 0u);                   // legacy count: 0 for format 7
  EXPECT_EQ(at<std::uint64_t>(b, 247), 5u);                   // number of point records
  EXPECT_EQ(at<std::uint64_t>(b, 255), 5u);                   // ... of return 1
  EXPECT_DOUBLE_EQ(at<double>(b, 131), 0.001);                // X scale
  EXPECT_DOUBLE_EQ(at<double>(b, 155), 500123.0);             // X offset
  EXPECT_DOUBLE_EQ(at<double>(b, 179), 500123.25 + 42.0);     // max X
  EXPECT_DOUBLE_EQ(at<double>(b, 187), 500123.25);            // min X
  EXPECT_DOUBLE_EQ(at<double>(b, 203), 5187654.125 - 13.0);   // min Y
  // The VLR: reserved, user id, record id 2112, length, description, the WKT with its NUL.
  EXPECT_EQ(std::string(b.data() + 377), "LASF_Projection");
  EXPECT_EQ(at<std::uint16_t>(b, 375 + 18), 2112);
  EXPECT_EQ(at<std::uint16_t>(b, 375 + 20), wkt_bytes);
  EXPECT_EQ(std::string(b.data() + 375 + 54), kWkt);
  // The second record: X = round((500133.75 - 500123) / 0.001), return 1 of 1, class 3, RGB.
  const std::size_t r = 375 + 54 + wkt_bytes + 36;
  EXPECT_EQ(at<std::int32_t>(b, r), 10750);
  EXPECT_EQ(at<std::int32_t>(b, r + 4), std::lround((5187654.125 - 3.25 - 5187641.0) / 0.001));
  EXPECT_EQ(static_cast<unsigned char>(b[r + 14]), 0x11);
  EXPECT_EQ(static_cast<unsigned char>(b[r + 16]), 3);
  EXPECT_EQ(at<std::uint16_t>(b, r + 30), 2570);
  EXPECT_EQ(at<std::uint16_t>(b, r + 32), 65534);
  EXPECT_EQ(at<std::uint16_t>(b, r + 34), 1);
}

TEST(Las, ReadsBackWhatItWritesToAMillimetre) {
  test::TempDir dir;
  io::LasHeader h;
  h.wkt = kWkt;
  const auto points = somePoints();
  io::writeLas(dir.file("a.las"), points, h);
  io::LasHeader back;
  const auto read = io::readLas(dir.file("a.las"), &back);
  EXPECT_EQ(back.wkt, kWkt);
  EXPECT_EQ(back.point_count, 5u);
  EXPECT_EQ(back.point_format, 7);
  ASSERT_EQ(read.size(), points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(read[i].x, points[i].x, 0.0005);
    EXPECT_NEAR(read[i].y, points[i].y, 0.0005);
    EXPECT_NEAR(read[i].z, points[i].z, 0.0005);
    EXPECT_EQ(read[i].rgb, points[i].rgb);
    EXPECT_EQ(read[i].classification, points[i].classification);
  }
  // No CRS, no VLR; an empty cloud is a valid file.
  io::writeLas(dir.file("b.las"), {}, io::LasHeader{});
  EXPECT_TRUE(io::readLas(dir.file("b.las"), &back).empty());
  EXPECT_TRUE(back.wkt.empty());
}

TEST(Las, BadCloudsAndBadFilesAreClearErrors) {
  test::TempDir dir;
  auto points = somePoints();
  points[2].z = std::numeric_limits<double>::quiet_NaN();
  EXPECT_THROW(io::writeLas(dir.file("nan.las"), points, {}), Error);
  points = somePoints();
  points[1].x = 1e9;  // 1e12 mm from the offset: beyond 32-bit integers
  EXPECT_THROW(io::writeLas(dir.file("far.las"), points, {}), Error);
  EXPECT_FALSE(test::runCommand("test -e " + dir.file("far.las")) == 0);

  io::writeLas(dir.file("ok.las"), somePoints(), {});
  const std::string good = test::readFile(dir.file("ok.las"));
  auto expectError = [&](std::string bytes, const std::string& field) {
    test::writeFile(dir.file("bad.las"), bytes);
    try {
      io::readLas(dir.file("bad.las"));
      ADD_FAILURE() << "no error for " << field;
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), field) << e.what();
      EXPECT_EQ(e.file(), dir.file("bad.las"));
    }
  };
  expectError(good.substr(0, good.size() - 10), "number of point records");
  expectError("PLY\n", "signature");
  std::string v12 = good;
  v12[25] = 2;
  expectError(v12, "version");
  std::string laz = good;
  laz[104] = static_cast<char>(7 | 0x80);
  expectError(laz, "point data format");
  // Scale factors, offsets and bounds (LAS 1.4 table 3, offsets 131, 155, 179): a zero, NaN or
  // huge scale, a non-finite offset, NaN bounds or bounds that do not hold the points.
  const auto patched = [&](std::size_t offset, double value) {
    std::string b = good;
    std::memcpy(&b[offset], &value, 8);
    return b;
  };
  expectError(patched(131, 0.0), "X scale factor");
  expectError(patched(139, std::nan("")), "Y scale factor");
  expectError(patched(147, 1e308), "Z scale factor");
  expectError(patched(155, std::numeric_limits<double>::infinity()), "X offset");
  expectError(patched(171, 1e308), "Z offset");
  expectError(patched(187, std::nan("")), "min / max X");         // min X
  expectError(patched(179, 500000.0), "min / max X");             // max X below the points
  expectError(patched(211, -1000.0), "min / max Z");              // max Z below the points
}

TEST(Las, StreamingVisitsEveryPointAndSummariesEscapeTheWkt) {
  test::TempDir dir;
  io::LasHeader h;
  h.wkt = "PROJCS[\"\x1b[2J evil\"]";
  io::writeLas(dir.file("a.las"), somePoints(), h);
  std::size_t visited = 0;
  double sum_x = 0;
  const io::LasHeader read = io::forEachLasPoint(dir.file("a.las"), [&](const io::LasPoint& p) {
    ++visited;
    sum_x += p.x;
  });
  EXPECT_EQ(visited, 5u);
  EXPECT_EQ(read.point_count, 5u);
  EXPECT_NEAR(sum_x, 5 * 500123.25 + 10.5 * 10, 1e-3);
  std::string out;
  ASSERT_EQ(test::runCommand(std::string(test::kCli) + " info " + dir.file("a.las"), &out), 0)
      << out;
  EXPECT_EQ(out.find('\x1b'), std::string::npos) << out;
  EXPECT_NE(out.find("CRS: \\x1B[2J evil"), std::string::npos) << out;
}

TEST(Las, ClassNamesMapToAsprsCodesAndAMapOverridesThem) {
  EXPECT_EQ(io::defaultAsprsCode("Road", 0), 11);
  EXPECT_EQ(io::defaultAsprsCode("building", 1), 6);
  EXPECT_EQ(io::defaultAsprsCode("tree", 2), 5);
  EXPECT_EQ(io::defaultAsprsCode("low vegetation", 3), 3);
  EXPECT_EQ(io::defaultAsprsCode("grass", 3), 3);
  EXPECT_EQ(io::defaultAsprsCode("water", 4), 9);
  EXPECT_EQ(io::defaultAsprsCode("bare soil", 5), 2);
  EXPECT_EQ(io::defaultAsprsCode("railway", 5), 10);
  EXPECT_EQ(io::defaultAsprsCode("car", 6), 70);  // user-definable: 64 + class id
  test::TempDir dir;
  test::writeFile(dir.file("map.json"), "{\"car\": 64, \"tree\": 4}");
  EXPECT_EQ(io::asprsCodes({"road", "tree", "car"}, dir.file("map.json")),
            (std::vector<int>{11, 4, 64}));
  test::writeFile(dir.file("unknown.json"), "{\"boat\": 64}");
  EXPECT_THROW(io::asprsCodes({"road"}, dir.file("unknown.json")), Error);
  test::writeFile(dir.file("range.json"), "{\"road\": 300}");
  EXPECT_THROW(io::asprsCodes({"road"}, dir.file("range.json")), Error);
  // 2^32 + 11 is not 11 (no silent wrap), 11.5 no code.
  for (const char* code : {"4294967307", "11.5", "-1", "\"11\""}) {
    test::writeFile(dir.file("wrap.json"), std::string("{\"road\": ") + code + "}");
    try {
      io::asprsCodes({"road"}, dir.file("wrap.json"));
      ADD_FAILURE() << code;
    } catch (const Error& e) {
      EXPECT_EQ(e.field(), "road") << e.what();
      EXPECT_NE(std::string(e.what()).find("an integer in [0, 255]"), std::string::npos) << e.what();
    }
  }
}

}  // namespace
}  // namespace sadsplat
