// PCD through sadsplat's own codec: exact round trips, files of PCL's writer (ascii, binary,
// binary_compressed), the semantic cloud, and damaged files as one-line errors.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/common/semantic_cloud.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/pcd.h"
#include "test_support/test_support.h"

#if SADSPLAT_HAVE_PCL_IO
#include <pcl/io/pcd_io.h>
#endif

namespace sadsplat {
namespace {

const std::vector<ClassInfo> kClasses = {{"a", {10, 20, 30}, "a"}, {"b", {40, 50, 60}, "b"}};

// Expects loading `path` as Gaussians to throw an Error naming the file with `needle` in it.
void expectPcdError(const std::string& path, const std::string& needle) {
  try {
    io::loadGaussianPcd(path);
    FAIL() << "expected an error containing: " << needle;
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

const char* kXyzHeader =
    "VERSION .7\nFIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nCOUNT 1 1 1\nWIDTH 1\n"
    "HEIGHT 1\nVIEWPOINT 0 0 0 1 0 0 0\nPOINTS 1\n";

TEST(Pcd, GaussianRoundTripIsBitExact) {
  test::TempDir dir;
  const auto cloud = test::randomGaussians(50, 21);
  io::savePcd(dir.file("g.pcd"), cloud);
  const auto back = io::loadGaussianPcd(dir.file("g.pcd"));
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << i;
  EXPECT_EQ(io::pcdContent(dir.file("g.pcd")), io::PcdContent::kGaussians);
}

TEST(Pcd, EmptyCloudRoundTrips) {
  test::TempDir dir;
  io::savePcd(dir.file("e.pcd"), pcl::PointCloud<GaussianPoint>());
  EXPECT_EQ(io::loadGaussianPcd(dir.file("e.pcd")).size(), 0u);
}

TEST(Pcd, SemanticCloudRoundTripsAndNamesItsContent) {
  test::TempDir dir;
  const auto cloud = toSemanticCloud(test::randomGaussians(30, 22, 2), kClasses);
  for (const char* name : {"s.pcd", "s.ply"}) {
    io::writeSemanticCloud(dir.file(name), cloud);
    EXPECT_EQ(io::cloudKind(dir.file(name)), io::CloudKind::kSemantic) << name;
    const auto back = io::readSemanticCloud(dir.file(name));
    ASSERT_EQ(back.size(), cloud.size()) << name;
    for (std::size_t i = 0; i < back.size(); ++i) {
      EXPECT_EQ(back[i].x, cloud[i].x);
      EXPECT_EQ(back[i].z, cloud[i].z);
      EXPECT_EQ(back[i].label, cloud[i].label);
      EXPECT_EQ(back[i].rgba & 0xffffffu, cloud[i].rgba & 0xffffffu) << name << " " << i;
    }
  }
}

#if SADSPLAT_HAVE_PCL_IO
TEST(Pcd, PclReadsOurSemanticCloud) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(30, 22, 2);
  io::savePcd(dir.file("s.pcd"), toSemanticCloud(cloud, kClasses));
  pcl::PointCloud<pcl::PointXYZRGBL> back;
  ASSERT_EQ(pcl::io::loadPCDFile(dir.file("s.pcd"), back), 0);
  ASSERT_EQ(back.size(), 30u);
  for (std::size_t i = 0; i < back.size(); ++i) {
    EXPECT_EQ(back[i].x, cloud[i].x);
    EXPECT_EQ(back[i].label, cloud[i].label);
    if (cloud[i].label != kUnlabelled) {
      EXPECT_EQ(back[i].b, kClasses[cloud[i].label].color[2]);
    }
  }
}

// What PCL's own writer makes, in each of its three encodings, reads back exactly.
TEST(Pcd, ReadsPclWrittenAsciiBinaryAndCompressedFiles) {
  test::TempDir dir;
  const auto cloud = test::randomGaussians(40, 23);
  pcl::PCDWriter writer;
  ASSERT_EQ(writer.writeBinary(dir.file("b.pcd"), cloud), 0);
  ASSERT_EQ(writer.writeBinaryCompressed(dir.file("c.pcd"), cloud), 0);
  ASSERT_EQ(writer.writeASCII(dir.file("a.pcd"), cloud, 9), 0);
  for (const char* name : {"b.pcd", "c.pcd"}) {
    const auto back = io::loadGaussianPcd(dir.file(name));
    ASSERT_EQ(back.size(), cloud.size()) << name;
    for (std::size_t i = 0; i < cloud.size(); ++i) {
      ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << name << " " << i;
    }
  }
  const auto ascii = io::loadGaussianPcd(dir.file("a.pcd"));
  ASSERT_EQ(ascii.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    EXPECT_FLOAT_EQ(ascii[i].x, cloud[i].x);
    EXPECT_FLOAT_EQ(ascii[i].feature[31], cloud[i].feature[31]);
    EXPECT_EQ(ascii[i].label, cloud[i].label);
  }
}

// Damaged compressed data is an error naming the data, never a crash (PCL's reader crashed).
TEST(Pcd, CorruptCompressedDataIsAnError) {
  test::TempDir dir;
  pcl::PCDWriter writer;
  ASSERT_EQ(writer.writeBinaryCompressed(dir.file("c.pcd"), test::randomGaussians(40, 24)), 0);
  std::string bytes = test::readFile(dir.file("c.pcd"));
  const std::size_t data = bytes.find("DATA binary_compressed\n") + 23;
  std::string sizes = bytes;
  sizes[data + 4] = 0;  // uncompressed size
  sizes[data + 5] = 0;
  test::writeFile(dir.file("sizes.pcd"), sizes);
  expectPcdError(dir.file("sizes.pcd"), "uncompressed size");
  std::string body = bytes;
  for (std::size_t k = data + 8; k < data + 40; ++k) body[k] = static_cast<char>(0xff);
  test::writeFile(dir.file("body.pcd"), body);
  expectPcdError(dir.file("body.pcd"), "binary_compressed");
}
#endif

TEST(Pcd, MissingFileOrFieldIsAnError) {
  test::TempDir dir;
  expectPcdError(dir.file("none.pcd"), "got missing");
  test::writeFile(dir.file("xyz.pcd"), std::string(kXyzHeader) + "DATA ascii\n1 2 3\n");
  try {
    io::loadGaussianPcd(dir.file("xyz.pcd"));
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "field f_dc");
  }
  EXPECT_THROW(io::loadSemanticPcd(dir.file("xyz.pcd")), Error);
  EXPECT_THROW(io::cloudKind(dir.file("xyz.pcd")), Error);
}

// The inputs that crashed PCL's reader or were accepted silently, as one-line errors.
TEST(Pcd, DamagedHeadersAndDataAreErrors) {
  test::TempDir dir;
  const auto check = [&](const std::string& name, const std::string& bytes,
                         const std::string& needle) {
    test::writeFile(dir.file(name), bytes);
    expectPcdError(dir.file(name), needle);
  };
  check("empty.pcd", "", "DATA line");
  check("word.pcd", "hello", "PCD header keyword");
  check("keyword.pcd", "VERSION .7\nFROB 1\nFIELDS x\n", "PCD header keyword");
  check("bare_data.pcd", "DATA\n", "ascii, binary or binary_compressed");
  check("no_fields.pcd", "DATA ascii\n", "FIELDS");
  check("size.pcd",
        "FIELDS x y z\nSIZE 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 1\nDATA ascii\n1 2 3\n",
        "SIZE: expected 3 values");
  check("points.pcd",
        "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 1\nHEIGHT 1\nPOINTS 7\nDATA ascii\n1 2 3\n",
        "POINTS");
  check("huge.pcd",
        "FIELDS x y z\nSIZE 4 4 4\nTYPE F F F\nWIDTH 4000000000\nHEIGHT 1\nPOINTS 4000000000\n"
        "DATA binary\n",
        "truncated");
  check("shortrow.pcd", std::string(kXyzHeader) + "DATA ascii\n1 2\n", "values on the line");
  check("badnum.pcd", std::string(kXyzHeader) + "DATA ascii\n1 2 x\n", "a number");
  check("trunc.pcd", std::string(kXyzHeader) + "DATA binary\nabc", "truncated");
  check("type.pcd", "FIELDS x\nSIZE 2\nTYPE F\nWIDTH 1\nHEIGHT 1\nDATA ascii\n1\n",
        "4 or 8 for TYPE F");
  // Rows with missing values and the semantic reader: the label must be an integer.
  test::writeFile(dir.file("sem.pcd"),
                  "FIELDS x y z rgb label\nSIZE 4 4 4 4 4\nTYPE F F F F I\nWIDTH 2\nHEIGHT 1\n"
                  "DATA ascii\n1 2 3 0 -1\n4 5 6 0 2\n");
  const auto sem = io::loadSemanticPcd(dir.file("sem.pcd"));
  ASSERT_EQ(sem.size(), 2u);
  EXPECT_EQ(sem[0].label, kUnlabelled);
  EXPECT_EQ(sem[1].label, 2u);
  test::writeFile(dir.file("sem_bad.pcd"),
                  "FIELDS x y z rgb label\nSIZE 4 4 4 4 4\nTYPE F F F F I\nWIDTH 1\nHEIGHT 1\n"
                  "DATA ascii\n1 2 3 0 -5\n");
  EXPECT_THROW(io::loadSemanticPcd(dir.file("sem_bad.pcd")), Error);
}

TEST(Pcd, AFifoIsAnErrorNotABlockingRead) {
  test::TempDir dir;
  ASSERT_EQ(test::runCommand("mkfifo " + dir.file("pipe.pcd")), 0);
  expectPcdError(dir.file("pipe.pcd"), "a regular file");
}

TEST(Pcd, EightByteFloatsBeyondFloatRangeAreErrors) {
  test::TempDir dir;
  const auto semanticError = [&](const std::string& path) -> std::string {
    try {
      io::loadSemanticPcd(path);
    } catch (const Error& e) {
      return e.what();
    }
    return "";
  };
  std::string header =
      "FIELDS x y z rgb label\nSIZE 8 4 4 4 4\nTYPE F F F F U\nCOUNT 1 1 1 1 1\nWIDTH 1\n"
      "HEIGHT 1\nPOINTS 1\nDATA ascii\n";
  test::writeFile(dir.file("big.pcd"), header + "1e300 0 0 0 1\n");
  EXPECT_NE(semanticError(dir.file("big.pcd")).find("point 0 field x: expected a finite number "
                                                    "within float range"),
            std::string::npos);
  test::writeFile(dir.file("inf.pcd"), header + "inf 0 0 0 1\n");
  EXPECT_NE(semanticError(dir.file("inf.pcd")).find("point 0 field x"), std::string::npos);
  test::writeFile(dir.file("nan.pcd"), header + "nan 0 0 0 1\n");
  const auto cloud = io::loadSemanticPcd(dir.file("nan.pcd"));  // NaN: PCL's invalid point
  EXPECT_FALSE(cloud.is_dense);
}

}  // namespace
}  // namespace sadsplat
