// COLMAP models: text and binary readers agree, writers round-trip, bad files are named.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/io/colmap.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kTinyScene;

void expectSameModel(const io::ColmapModel& a, const io::ColmapModel& b) {
  ASSERT_EQ(a.cameras.size(), b.cameras.size());
  ASSERT_EQ(a.images.size(), b.images.size());
  ASSERT_EQ(a.points.size(), b.points.size());
  for (std::size_t i = 0; i < a.cameras.size(); ++i) {
    EXPECT_EQ(a.cameras[i].model, b.cameras[i].model);
    EXPECT_EQ(a.cameras[i].params, b.cameras[i].params);
    EXPECT_EQ(a.cameras[i].width, b.cameras[i].width);
  }
  for (std::size_t i = 0; i < a.images.size(); ++i) {
    EXPECT_EQ(a.images[i].name, b.images[i].name);
    EXPECT_EQ(a.images[i].qvec, b.images[i].qvec);
    EXPECT_EQ(a.images[i].tvec, b.images[i].tvec);
    ASSERT_EQ(a.images[i].points2d.size(), b.images[i].points2d.size());
    for (std::size_t k = 0; k < a.images[i].points2d.size(); ++k) {
      EXPECT_EQ(a.images[i].points2d[k].x, b.images[i].points2d[k].x);
      EXPECT_EQ(a.images[i].points2d[k].point3d_id, b.images[i].points2d[k].point3d_id);
    }
  }
  for (std::size_t i = 0; i < a.points.size(); ++i) {
    EXPECT_EQ(a.points[i].xyz, b.points[i].xyz);
    EXPECT_EQ(a.points[i].rgb, b.points[i].rgb);
    EXPECT_EQ(a.points[i].track, b.points[i].track);
  }
}

void expectError(const std::string& dir, const std::string& file_suffix,
                 const std::string& needle) {
  try {
    io::readColmapModel(dir);
    FAIL() << "expected an error containing " << needle;
  } catch (const Error& e) {
    EXPECT_NE(e.file().find(file_suffix), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

TEST(Colmap, TextAndIndependentlyWrittenBinaryAgree) {
  const auto text = io::readColmapModel(kTinyScene + "/sparse/0");
  const auto binary =
      io::readColmapModel(std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene_colmap_bin");
  EXPECT_EQ(text.images.size(), 8u);
  EXPECT_EQ(text.points.size(), 400u);
  EXPECT_EQ(text.cameras[0].model, io::CameraModel::kPinhole);
  expectSameModel(text, binary);
}

TEST(Colmap, WritersRoundTripBothFormats) {
  const auto model = io::readColmapModel(kTinyScene + "/sparse/0");
  test::TempDir text_dir, bin_dir;
  io::writeColmapText(text_dir.path(), model);
  io::writeColmapBinary(bin_dir.path(), model);
  expectSameModel(model, io::readColmapModel(text_dir.path()));
  expectSameModel(model, io::readColmapModel(bin_dir.path()));
}

TEST(Colmap, ReadsEveryCameraModel) {
  test::TempDir dir;
  io::ColmapModel model;
  const std::vector<std::pair<io::CameraModel, std::vector<double>>> cams = {
      {io::CameraModel::kSimplePinhole, {50, 32, 24}},
      {io::CameraModel::kPinhole, {50, 51, 32, 24}},
      {io::CameraModel::kSimpleRadial, {50, 32, 24, 0.01}},
      {io::CameraModel::kRadial, {50, 32, 24, 0.01, -0.002}},
      {io::CameraModel::kOpenCV, {50, 51, 32, 24, 0.01, -0.002, 0.001, 0.0005}}};
  for (std::size_t i = 0; i < cams.size(); ++i) {
    io::ColmapCamera c;
    c.id = static_cast<std::uint32_t>(i + 1);
    c.model = cams[i].first;
    c.width = 64;
    c.height = 48;
    c.params = cams[i].second;
    model.cameras.push_back(c);
  }
  io::writeColmapText(dir.path(), model);
  const auto back = io::readColmapModel(dir.path());
  ASSERT_EQ(back.cameras.size(), 5u);
  for (std::size_t i = 0; i < cams.size(); ++i) {
    EXPECT_EQ(back.cameras[i].model, cams[i].first);
    EXPECT_EQ(back.cameras[i].params, cams[i].second);
  }
}

TEST(Colmap, BadModelsGiveClearErrors) {
  test::TempDir dir;
  expectError(dir.path(), "cameras.txt", "missing");

  const auto model = io::readColmapModel(kTinyScene + "/sparse/0");
  io::writeColmapText(dir.path(), model);
  test::writeFile(dir.file("cameras.txt"), "1 FISHEYE_X 64 48 50 32 24\n");
  expectError(dir.path(), "cameras.txt", "MODEL: expected one of SIMPLE_PINHOLE");

  test::writeFile(dir.file("cameras.txt"), "1 PINHOLE 64 48 50 32 24\n");
  expectError(dir.path(), "cameras.txt", "4 parameters for PINHOLE");

  test::writeFile(dir.file("cameras.txt"), "1 PINHOLE 64 48 nan 50 32 24\n");
  expectError(dir.path(), "cameras.txt", "finite");

  test::writeFile(dir.file("cameras.txt"), "7 PINHOLE 64 48 50 50 32 24\n");
  expectError(dir.path(), "images", "the id of a camera");

  test::TempDir bin;
  io::writeColmapBinary(bin.path(), model);
  const std::string images = test::readFile(bin.file("images.bin"));
  test::writeFile(bin.file("images.bin"), images.substr(0, images.size() / 2));
  expectError(bin.path(), "images.bin", "truncated");

  std::string cams = test::readFile(bin.file("cameras.bin"));
  cams[12] = 9;  // model_id of the first camera
  test::writeFile(bin.file("cameras.bin"), cams);
  expectError(bin.path(), "cameras.bin", "model_id");
}

}  // namespace
}  // namespace sadsplat
