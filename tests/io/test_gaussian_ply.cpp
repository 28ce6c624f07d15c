// The 3DGS PLY codec: exact round trips, the standard layout, files of other tools, errors, and
// the readers of PCL and Open3D.
#include <gtest/gtest.h>

#include <chrono>
#include <cmath>
#include <cstring>
#include <fstream>

#include "sadsplat/common/error.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_checks.h"
#include "sadsplat/io/gaussian_ply.h"
#include "test_support/test_support.h"

#if SADSPLAT_HAVE_PCL_IO
#include <pcl/PCLPointCloud2.h>
#include <pcl/io/ply_io.h>
#endif

namespace sadsplat {
namespace {

using io::PlyFileInfo;
using io::readGaussianPly;
using io::writeGaussianPly;

std::string headerOf(const std::string& path) {
  const std::string bytes = test::readFile(path);
  return bytes.substr(0, bytes.find("end_header\n") + 11);
}

// Expects readGaussianPly(path) to throw an Error whose message contains `needle`.
void expectReadError(const std::string& path, const std::string& needle) {
  try {
    readGaussianPly(path);
    FAIL() << "expected an error containing: " << needle;
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(GaussianPly, RoundTripIsBitExact) {
  test::TempDir dir;
  const auto cloud = test::randomGaussians(257, 11);
  writeGaussianPly(dir.file("a.ply"), cloud);
  PlyFileInfo info;
  const auto back = readGaussianPly(dir.file("a.ply"), &info);
  ASSERT_EQ(back.size(), cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    ASSERT_TRUE(bitwiseEqual(back[i], cloud[i])) << "point " << i;
  }
  EXPECT_EQ(info.sh_degree, 3);
  EXPECT_TRUE(info.has_semantic);
  EXPECT_EQ(info.feature_dim, 32);
  EXPECT_TRUE(info.ignored_properties.empty());
}

TEST(GaussianPly, WritesTheStandardLayoutThenSemanticProperties) {
  test::TempDir dir;
  writeGaussianPly(dir.file("a.ply"), test::randomGaussians(3, 1));
  std::string want =
      "ply\nformat binary_little_endian 1.0\ncomment written by sadsplat\n"
      "element vertex 3\n";
  for (const char* n : {"x", "y", "z", "nx", "ny", "nz", "f_dc_0", "f_dc_1", "f_dc_2"}) {
    want += std::string("property float ") + n + "\n";
  }
  for (int k = 0; k < 45; ++k) want += "property float f_rest_" + std::to_string(k) + "\n";
  want += "property float opacity\n";
  for (int k = 0; k < 3; ++k) want += "property float scale_" + std::to_string(k) + "\n";
  for (int k = 0; k < 4; ++k) want += "property float rot_" + std::to_string(k) + "\n";
  for (int k = 0; k < 32; ++k) want += "property float feature_" + std::to_string(k) + "\n";
  want += "property float log_alpha\nproperty float confidence\nproperty int label\nend_header\n";
  EXPECT_EQ(headerOf(dir.file("a.ply")), want);
  // 62 standard floats + 34 semantic floats + 1 uint per vertex.
  EXPECT_EQ(test::readFile(dir.file("a.ply")).size(), want.size() + 3 * 97 * 4);
}

TEST(GaussianPly, LowerShDegreeWritesFewerCoefficientsChannelMajor) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(5, 2);
  io::PlyWriteOptions options;
  options.sh_degree = 1;
  options.semantic = false;
  writeGaussianPly(dir.file("d1.ply"), cloud, options);
  PlyFileInfo info;
  const auto back = readGaussianPly(dir.file("d1.ply"), &info);
  EXPECT_EQ(info.sh_degree, 1);
  EXPECT_FALSE(info.has_semantic);
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    for (int c = 0; c < 3; ++c) {
      for (int k = 0; k < 15; ++k) {
        const float want = k < 3 ? cloud[i].f_rest[c * 15 + k] : 0.f;
        EXPECT_EQ(back[i].f_rest[c * 15 + k], want) << "point " << i << " c " << c << " k " << k;
      }
    }
    EXPECT_EQ(back[i].feature[0], 0.f);
    EXPECT_EQ(back[i].label, kUnlabelled);
    EXPECT_EQ(back[i].opacity, cloud[i].opacity);
  }
}

TEST(GaussianPly, ReadsAsciiFilesOfOtherToolsWithoutNormalsAndWithExtras) {
  test::TempDir dir;
  // Degree 1 (9 rest coefficients), no normals, extra properties of other types, CRLF lines.
  std::string text =
      "ply\r\nformat ascii 1.0\r\ncomment made by another trainer\r\nelement vertex 2\r\n"
      "property float x\r\nproperty float y\r\nproperty float z\r\n"
      "property float f_dc_0\r\nproperty float f_dc_1\r\nproperty float f_dc_2\r\n";
  for (int k = 0; k < 9; ++k) text += "property float f_rest_" + std::to_string(k) + "\r\n";
  text +=
      "property float opacity\r\nproperty double scale_0\r\nproperty float scale_1\r\n"
      "property float scale_2\r\nproperty float rot_0\r\nproperty float rot_1\r\n"
      "property float rot_2\r\nproperty float rot_3\r\nproperty uchar red\r\n"
      "element face 0\r\nproperty list uchar int vertex_indices\r\nend_header\r\n"
      "1 2 3 0.1 0.2 0.3 10 11 12 20 21 22 30 31 32 -2 -1.5 -1.25 -1 1 0 0 0 255\r\n"
      "4 5 6 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0 0.5 0.5 0.5 0.5 7\r\n";
  test::writeFile(dir.file("other.ply"), text);
  PlyFileInfo info;
  const auto cloud = readGaussianPly(dir.file("other.ply"), &info);
  ASSERT_EQ(cloud.size(), 2u);
  EXPECT_EQ(info.format, "ascii");
  EXPECT_EQ(info.sh_degree, 1);
  EXPECT_FALSE(info.has_normals);
  EXPECT_EQ(info.ignored_properties, std::vector<std::string>{"red"});
  EXPECT_EQ(cloud[0].z, 3.f);
  EXPECT_EQ(cloud[0].f_dc[2], 0.3f);
  EXPECT_EQ(cloud[0].f_rest[0 * 15 + 0], 10.f);  // R, coefficient 1
  EXPECT_EQ(cloud[0].f_rest[1 * 15 + 1], 21.f);  // G, coefficient 2
  EXPECT_EQ(cloud[0].f_rest[2 * 15 + 2], 32.f);  // B, coefficient 3
  EXPECT_EQ(cloud[0].f_rest[2 * 15 + 3], 0.f);
  EXPECT_EQ(cloud[0].opacity, -2.f);
  EXPECT_EQ(cloud[0].scale[0], -1.5f);
  EXPECT_EQ(cloud[1].rot[3], 0.5f);
  EXPECT_EQ(cloud[1].nx, 0.f);
  EXPECT_EQ(cloud[1].label, kUnlabelled);
}

TEST(GaussianPly, ReadsBigEndianAndSkipsElementsBeforeTheVertices) {
  test::TempDir dir;
  std::string bytes =
      "ply\nformat binary_big_endian 1.0\nelement meta 1\nproperty list uchar short ids\n"
      "element vertex 1\n";
  const char* names[] = {"x",       "y",       "z",       "f_dc_0", "f_dc_1", "f_dc_2", "opacity",
                         "scale_0", "scale_1", "scale_2", "rot_0",  "rot_1",  "rot_2",  "rot_3"};
  for (const char* n : names) bytes += std::string("property float ") + n + "\n";
  bytes += "end_header\n";
  bytes += std::string("\x02\x00\x01\x00\x02", 5);  // meta: list of two shorts
  for (int i = 0; i < 14; ++i) {
    const float v = 0.5f * static_cast<float>(i);
    std::uint32_t u;
    std::memcpy(&u, &v, 4);
    for (int b = 3; b >= 0; --b) bytes.push_back(static_cast<char>((u >> (8 * b)) & 0xff));
  }
  test::writeFile(dir.file("be.ply"), bytes);
  const auto cloud = readGaussianPly(dir.file("be.ply"));
  ASSERT_EQ(cloud.size(), 1u);
  EXPECT_EQ(cloud[0].y, 0.5f);
  EXPECT_EQ(cloud[0].rot[3], 6.5f);
}

TEST(GaussianPly, ErrorsNameTheFileAndTheProblem) {
  test::TempDir dir;
  expectReadError(dir.file("missing.ply"), "existing, readable file");

  test::writeFile(dir.file("magic.ply"), "PLY?\n");
  expectReadError(dir.file("magic.ply"), "magic");

  test::writeFile(dir.file("noscale.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 1\nproperty float x\nproperty float y\n"
                  "property float z\nend_header\n1 2 3\n");
  expectReadError(dir.file("noscale.ply"), "vertex property f_dc_0");

  writeGaussianPly(dir.file("full.ply"), test::randomGaussians(4, 5));
  const std::string full = test::readFile(dir.file("full.ply"));
  test::writeFile(dir.file("truncated.ply"), full.substr(0, full.size() - 10));
  expectReadError(dir.file("truncated.ply"), "truncated");

  auto cloud = test::randomGaussians(2, 6);
  cloud[1].scale[1] = std::numeric_limits<float>::quiet_NaN();
  // The writer refuses what the reader would refuse, naming the Gaussian and the field.
  try {
    writeGaussianPly(dir.file("nan.ply"), cloud);
    ADD_FAILURE() << "a NaN was written";
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "Gaussian 1 scale_1");
  }
  EXPECT_FALSE(io::pathExists(dir.file("nan.ply")));
  // A NaN in a file: vertex 1's scale_1 (float 56 of 97 per record) patched in.
  cloud[1].scale[1] = 0.5f;
  writeGaussianPly(dir.file("nan.ply"), cloud);
  std::string bytes = test::readFile(dir.file("nan.ply"));
  const std::size_t data = bytes.find("end_header\n") + 11;
  const float nan = std::numeric_limits<float>::quiet_NaN();
  std::memcpy(&bytes[data + (97 + 56) * 4], &nan, 4);
  test::writeFile(dir.file("nan.ply"), bytes);
  expectReadError(dir.file("nan.ply"), "vertex 1 property scale_1: expected a finite number");

  std::string odd = "ply\nformat ascii 1.0\nelement vertex 0\n";
  for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0",
                        "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3", "f_rest_0"}) {
    odd += std::string("property float ") + n + "\n";
  }
  test::writeFile(dir.file("rest.ply"), odd + "end_header\n");
  expectReadError(dir.file("rest.ply"), "0, 9, 24 or 45");

  test::writeFile(dir.file("type.ply"),
                  "ply\nformat ascii 1.0\nelement vertex 0\nproperty float128 x\nend_header\n");
  expectReadError(dir.file("type.ply"), "PLY scalar type");
}

TEST(GaussianPly, FailedWriteLeavesNoFileBehind) {
  test::TempDir dir;
  test::writeFile(dir.file("plain"), "a file, not a directory");
  EXPECT_THROW(writeGaussianPly(dir.file("plain/a.ply"), test::randomGaussians(1, 1)), Error);
  // A missing directory is created: outputs may name nested paths that do not exist yet.
  writeGaussianPly(dir.file("new/nested/a.ply"), test::randomGaussians(2, 1));
  EXPECT_EQ(readGaussianPly(dir.file("new/nested/a.ply")).size(), 2u);
}

// Counts in a header are checked against the bytes present before they allocate or loop: the
// inputs a fuzzer found (huge counts, a huge element before the vertices, counts that are not
// decimal) are one-line errors, not bad_alloc, a hang or a silently wrong count.
TEST(GaussianPly, HeaderCountsAreCheckedAgainstTheFile) {
  test::TempDir dir;
  writeGaussianPly(dir.file("ok.ply"), test::randomGaussians(3, 2));
  const std::string ok = test::readFile(dir.file("ok.ply"));
  const auto edit = [&](const std::string& from, const std::string& to) {
    std::string bytes = ok;
    bytes.replace(bytes.find(from), from.size(), to);
    return bytes;
  };
  test::writeFile(dir.file("huge.ply"), edit("element vertex 3", "element vertex 5000000000"));
  expectReadError(dir.file("huge.ply"), "element vertex: expected 5000000000 items");
  test::writeFile(dir.file("toolarge.ply"),
                  edit("element vertex 3", "element vertex 99999999999999999999"));
  expectReadError(dir.file("toolarge.ply"), "decimal count");
  test::writeFile(dir.file("hex.ply"), edit("element vertex 3", "element vertex 0x28"));
  expectReadError(dir.file("hex.ply"), "decimal count");
  test::writeFile(dir.file("suffix.ply"), edit("element vertex 3", "element vertex 1abc"));
  expectReadError(dir.file("suffix.ply"), "decimal count");
  // An element without properties before the vertices, with a huge count, used to loop forever.
  test::writeFile(dir.file("empty_elem.ply"),
                  edit("element vertex 3", "element junk 900000000000\nelement vertex 3"));
  const auto start = std::chrono::steady_clock::now();
  const auto back = readGaussianPly(dir.file("empty_elem.ply"));
  EXPECT_EQ(back.size(), 3u);
  EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 5.0);
  test::writeFile(
      dir.file("big_elem.ply"),
      edit("element vertex 3", "element junk 90000000\nproperty float a\nelement vertex 3"));
  expectReadError(dir.file("big_elem.ply"), "element junk: expected 90000000 items");
  // A list whose length runs past the end of the file.
  std::string list =
      "ply\nformat ascii 1.0\nelement face 1\nproperty list uchar int idx\n"
      "element vertex 0\n";
  for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0",
                        "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
    list += std::string("property float ") + n + "\n";
  }
  test::writeFile(dir.file("list.ply"), list + "end_header\n200 1 2\n");
  expectReadError(dir.file("list.ply"), "list idx");
}

TEST(GaussianPly, LabelIsAnIntWithMinusOneForNoClass) {
  test::TempDir dir;
  auto cloud = test::randomGaussians(4, 3);
  cloud[0].label = kUnlabelled;
  cloud[1].label = 2;
  writeGaussianPly(dir.file("a.ply"), cloud);
  EXPECT_NE(headerOf(dir.file("a.ply")).find("property int label\n"), std::string::npos);
  const auto back = readGaussianPly(dir.file("a.ply"));
  EXPECT_EQ(back[0].label, kUnlabelled);
  EXPECT_EQ(back[1].label, 2u);
}

TEST(GaussianPly, AFifoIsAnErrorNotABlockingRead) {
  test::TempDir dir;
  ASSERT_EQ(test::runCommand("mkfifo " + dir.file("pipe.ply")), 0);
  expectReadError(dir.file("pipe.ply"), "a regular file");
}

#if SADSPLAT_HAVE_PCL_IO
TEST(GaussianPly, PclPlyReaderAcceptsOurFiles) {
  test::TempDir dir;
  const auto cloud = test::randomGaussians(10, 8);
  writeGaussianPly(dir.file("a.ply"), cloud);
  pcl::PCLPointCloud2 blob;
  pcl::PLYReader reader;
  ASSERT_EQ(reader.read(dir.file("a.ply"), blob), 0);
  EXPECT_EQ(blob.width * blob.height, 10u);
  ASSERT_EQ(blob.fields.size(), 97u);
  EXPECT_EQ(blob.fields[6].name, "f_dc_0");
  EXPECT_EQ(blob.fields.back().name, "label");
  float opacity = 0.f;
  for (const auto& f : blob.fields) {
    if (f.name == "opacity") std::memcpy(&opacity, &blob.data[3 * blob.point_step + f.offset], 4);
  }
  EXPECT_EQ(opacity, cloud[3].opacity);
}
#endif

TEST(GaussianPly, Open3dTensorReaderKeepsTheProperties) {
  std::string probe;
  if (test::runCommand("/usr/bin/python3 -c 'import open3d'", &probe) != 0) {
    GTEST_SKIP()
        << "Debian's python3-open3d is not installed (scripts/setup_debian.sh installs it)";
  }
  test::TempDir dir;
  auto cloud = test::randomGaussians(6, 9);
  cloud[0].label = kUnlabelled;
  cloud[1].label = 3;
  writeGaussianPly(dir.file("a.ply"), cloud);
  const std::string script =
      "import open3d as o3d, sys\n"
      "pc = o3d.t.io.read_point_cloud(sys.argv[1])\n"
      "print(len(pc.point.positions), float(pc.point.opacity[2][0].item()), "
      "float(pc.point.feature_31[4][0].item()), float(pc.point.f_rest_44[0][0].item()), "
      "int(pc.point.label[1][0].item()), int(pc.point.label[0][0].item()))\n";
  test::writeFile(dir.file("probe.py"), script);
  std::string out;
  ASSERT_EQ(
      test::runCommand("/usr/bin/python3 " + dir.file("probe.py") + " " + dir.file("a.ply"), &out),
      0)
      << out;
  std::istringstream in(out.substr(out.find_last_of('\n', out.size() - 2) + 1));
  std::size_t n = 0;
  float opacity = 0, feature = 0, rest = 0;
  int label1 = 0, label0 = 0;
  in >> n >> opacity >> feature >> rest >> label1 >> label0;
  // Open3D 0.16 skips `uint` properties: the label is an int so that it survives.
  EXPECT_EQ(label1, 3) << out;
  EXPECT_EQ(label0, -1) << out;
  EXPECT_EQ(n, 6u) << out;
  EXPECT_FLOAT_EQ(opacity, cloud[2].opacity);
  EXPECT_FLOAT_EQ(feature, cloud[4].feature[31]);
  EXPECT_FLOAT_EQ(rest, cloud[0].f_rest[44]);
}

// An ascii 3DGS PLY of one Gaussian whose values are given as text (x y z f_dc_0..2 opacity
// scale_0..2 rot_0..3), with `extra_header` lines after the vertex element.
std::string asciiPly(const std::string& values, const std::string& extra_header = "") {
  std::string text = "ply\nformat ascii 1.0\nelement vertex 1\n";
  for (const char* n : {"x", "y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0",
                        "scale_1", "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
    text += std::string("property float ") + n + "\n";
  }
  return text + extra_header + "end_header\n" + values + "\n";
}

// Values are checked as the floats they become and against the plausible ranges
// (gaussian_checks.h): nothing reads as a silent +inf or an absurd coordinate.
TEST(GaussianPly, ValuesBeyondFloatRangeOrPlausibilityAreErrors) {
  test::TempDir dir;
  const auto check = [&](const std::string& name, const std::string& values,
                         const std::string& needle) {
    test::writeFile(dir.file(name), asciiPly(values));
    expectReadError(dir.file(name), needle);
  };
  check("big.ply", "1e39 0 0 0 0 0 0 0 0 0 1 0 0 0", "vertex 0 property x: expected a finite number within float range");
  check("far.ply", "-3.4e38 0 0 0 0 0 0 0 0 0 1 0 0 0", "Gaussian 0 x: expected a coordinate within +-1e7");
  check("scale.ply", "0 0 0 0 0 0 0 1e30 0 0 1 0 0 0", "Gaussian 0 scale_0: expected a log-scale within +-50");
  // A binary double of 1e300 is +inf as a float.
  std::string header = "ply\nformat binary_little_endian 1.0\nelement vertex 1\nproperty double x\n";
  for (const char* n : {"y", "z", "f_dc_0", "f_dc_1", "f_dc_2", "opacity", "scale_0", "scale_1",
                        "scale_2", "rot_0", "rot_1", "rot_2", "rot_3"}) {
    header += std::string("property float ") + n + "\n";
  }
  std::string bytes = header + "end_header\n";
  const double huge = 1e300;
  bytes.append(reinterpret_cast<const char*>(&huge), 8);
  bytes.append(13 * 4, '\0');
  test::writeFile(dir.file("double.ply"), bytes);
  expectReadError(dir.file("double.ply"), "property x: expected a finite number within float range");
}

// What 3DGS decoders make of an alpha byte of 255 (+inf) reads as an opaque Gaussian, counted.
TEST(GaussianPly, InfiniteOpacityIsClampedAndCounted) {
  test::TempDir dir;
  test::writeFile(dir.file("inf.ply"), asciiPly("1 2 3 0 0 0 inf 0 0 0 1 0 0 0"));
  PlyFileInfo info;
  const auto cloud = readGaussianPly(dir.file("inf.ply"), &info);
  EXPECT_EQ(info.clamped_opacities, 1u);
  EXPECT_EQ(cloud[0].opacity, io::kMaxOpacityLogit);
  test::writeFile(dir.file("ninf.ply"), asciiPly("1 2 3 0 0 0 -inf 0 0 0 1 0 0 0"));
  EXPECT_EQ(readGaussianPly(dir.file("ninf.ply"))[0].opacity, -io::kMaxOpacityLogit);
  test::writeFile(dir.file("nan.ply"), asciiPly("1 2 3 0 0 0 nan 0 0 0 1 0 0 0"));
  expectReadError(dir.file("nan.ply"), "opacity");
}

// An element declared after the vertices (10^9 camera records) without its bytes is a
// truncated file, not a complete one.
TEST(GaussianPly, TrailingElementsMustBeComplete) {
  test::TempDir dir;
  test::writeFile(dir.file("cam.ply"), asciiPly("1 2 3 0 0 0 0 0 0 0 1 0 0 0",
                                                "element camera 1000000000\nproperty float fx\n"));
  expectReadError(dir.file("cam.ply"), "element camera");
  test::writeFile(dir.file("cam1.ply"), asciiPly("1 2 3 0 0 0 0 0 0 0 1 0 0 0",
                                                 "element camera 1\nproperty float fx\n") +
                                            "500\n");
  EXPECT_EQ(readGaussianPly(dir.file("cam1.ply")).size(), 1u);
}

}  // namespace
}  // namespace sadsplat
