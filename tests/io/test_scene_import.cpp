// Scene directory import: roles, resizing, undistortion, label maps and every input error.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/image_file.h"
#include "sadsplat/io/scene_import.h"
#include "test_support/test_support.h"

#if SADSPLAT_HAVE_OPENCV
#include <opencv2/imgcodecs.hpp>
#endif

namespace sadsplat {
namespace {

using test::kTinyScene;

class SceneImport : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  }
  // A writable copy of the fixture scene.
  std::string copy() { return test::copyTree(kTinyScene, tmp_.file("scene")); }

  void expectError(const std::string& dir, const std::string& file_suffix,
                   const std::string& needle, const io::ImportOptions& options = {}) {
    try {
      io::importScene(dir, options);
      FAIL() << "expected an error containing " << needle;
    } catch (const Error& e) {
      EXPECT_NE(e.file().find(file_suffix), std::string::npos) << e.what();
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }

  test::TempDir tmp_;
};

TEST_F(SceneImport, ReadsTheFixtureWithRolesLabelsAndPoints) {
  const io::Scene scene = io::importScene(kTinyScene);
  ASSERT_EQ(scene.views.size(), 8u);
  ASSERT_EQ(scene.classes.size(), 3u);
  EXPECT_EQ(scene.classes[2].name, "building");
  EXPECT_EQ(scene.points.size(), 400u);
  const io::View& v0 = scene.views[0];
  EXPECT_EQ(v0.name, "view_000.png");
  EXPECT_TRUE(v0.train && v0.labelled && !v0.test);
  EXPECT_TRUE(scene.views[2].test && !scene.views[2].train);
  EXPECT_FALSE(scene.views[1].labelled);
  EXPECT_FALSE(scene.views[1].labels.empty());  // ground truth exists for every view
  ASSERT_EQ(v0.labels.pixels.size(), 64u * 48u);
  EXPECT_EQ(v0.camera.width, 64);
  EXPECT_DOUBLE_EQ(v0.camera.fx, 52.0);
  // The fixture's corners are sky (ignore) in view 0; its centre sees the ground.
  EXPECT_EQ(v0.labels.at(0, 0), io::kIgnoreLabel);
  EXPECT_NE(v0.labels.at(32, 30), io::kIgnoreLabel);
  EXPECT_EQ(v0.mask.at(0, 0), 255);
  EXPECT_EQ(v0.rgb.channels, 3);
}

TEST_F(SceneImport, ResizingScalesImagesAndIntrinsics) {
  io::ImportOptions options;
  options.scale = 0.5;
  const io::Scene scene = io::importScene(kTinyScene, options);
  const auto& cam = scene.views[0].camera;
  EXPECT_EQ(cam.width, 32);
  EXPECT_EQ(cam.height, 24);
  EXPECT_DOUBLE_EQ(cam.fx, 26.0);
  EXPECT_DOUBLE_EQ(cam.cx, 16.0);
  EXPECT_EQ(scene.views[0].labels.pixels.size(), 32u * 24u);
  options.scale = 1.5;
  expectError(kTinyScene, "<import options>", "(0, 1]", options);
}

TEST_F(SceneImport, UndistortsRadialCamerasAndMasksInvalidPixels) {
  const std::string dir = copy();
  auto model = io::readColmapModel(dir + "/sparse/0");
  model.cameras[0].model = io::CameraModel::kOpenCV;
  model.cameras[0].params = {52, 52, 32, 24, 0.0, 0.0, 0.0, 0.0};
  io::writeColmapText(dir + "/sparse/0", model);
  const io::Scene zero = io::importScene(dir);
  const io::Scene plain = io::importScene(kTinyScene);
  // Zero distortion: identical pixels and labels.
  EXPECT_EQ(zero.views[0].rgb.pixels, plain.views[0].rgb.pixels);
  EXPECT_EQ(zero.views[0].labels.pixels, plain.views[0].labels.pixels);

  model.cameras[0].model = io::CameraModel::kSimpleRadial;
  model.cameras[0].params = {52, 32, 24, 0.4};  // pincushion: the corners fall outside
  io::writeColmapText(dir + "/sparse/0", model);
  const io::Scene warped = io::importScene(dir);
  const auto& v = warped.views[0];
  EXPECT_EQ(v.mask.at(0, 0), 0);
  EXPECT_EQ(v.labels.at(0, 0), io::kIgnoreLabel);
  EXPECT_EQ(v.mask.at(32, 24), 255);
  EXPECT_EQ(v.rgb.at(32, 24, 1), plain.views[0].rgb.at(32, 24, 1));
  EXPECT_DOUBLE_EQ(v.camera.fx, 52.0);
}

#if SADSPLAT_HAVE_OPENCV
// masks/<image>.png or masks/<stem>.png: 0 = leave the pixel out (of the losses), else keep.
TEST_F(SceneImport, MasksKeepPixelsOutAndTakeTheirLabels) {
  const std::string dir = copy();
  io::makeDirectory(dir + "/masks");
  cv::Mat mask(48, 64, CV_8UC1, cv::Scalar(255));
  mask(cv::Rect(20, 10, 12, 8)).setTo(0);
  ASSERT_TRUE(cv::imwrite(dir + "/masks/view_000.png.png", mask));  // COLMAP's name
  cv::Mat colour(48, 64, CV_8UC3, cv::Scalar(0, 0, 200));
  colour(cv::Rect(0, 0, 5, 5)).setTo(cv::Scalar(0, 0, 0));
  ASSERT_TRUE(cv::imwrite(dir + "/masks/view_001.png", colour));  // the stem's name, colour
  const io::Scene scene = io::importScene(dir);
  const io::View& v0 = scene.views[0];
  EXPECT_EQ(v0.mask.at(25, 12), 0);
  EXPECT_EQ(v0.labels.at(25, 12), io::kIgnoreLabel);
  EXPECT_EQ(v0.mask.at(40, 30), 255);
  EXPECT_NE(v0.labels.at(40, 30), io::kIgnoreLabel);
  EXPECT_EQ(scene.views[1].mask.at(2, 2), 0);
  EXPECT_EQ(scene.views[1].mask.at(30, 30), 255);
  EXPECT_EQ(std::count(scene.views[2].mask.pixels.begin(), scene.views[2].mask.pixels.end(), 0), 0);
  // Resized with the image.
  io::ImportOptions half;
  half.scale = 0.5;
  EXPECT_EQ(io::importScene(dir, half).views[0].mask.at(12, 6), 0);
  // A mask of another size is an error naming it.
  ASSERT_TRUE(cv::imwrite(dir + "/masks/view_001.png", cv::Mat(10, 10, CV_8UC1, cv::Scalar(0))));
  expectError(dir, "masks/view_001.png", "64x48");
}
#endif

// An optional file that is there but cannot be read (a dangling or looping symbolic link) is an
// error naming it, not a scene without it; a looping link in an annotation folder likewise.
TEST_F(SceneImport, LinksThatCannotBeFollowedAreErrorsNotAbsentFiles) {
  {
    const std::string dir = test::copyTree(kTinyScene, tmp_.file("dangling"));
    std::filesystem::remove(dir + "/classes.json");
    std::filesystem::create_symlink(dir + "/nowhere.json", dir + "/classes.json");
    expectError(dir, "classes.json", "symbolic link");
  }
  {
    const std::string dir = test::copyTree(kTinyScene, tmp_.file("looping"));
    std::filesystem::create_symlink("georeference.json", dir + "/georeference.json");  // a loop
    expectError(dir, "georeference.json", "symbolic link");
  }
  {
    const std::string dir = test::copyTree(kTinyScene, tmp_.file("annotated"));
    io::makeDirectory(dir + "/annotations");
    std::filesystem::create_symlink("loop.json", dir + "/annotations/loop.json");
    io::ImportOptions options;
    options.annotations = dir + "/annotations";
    expectError(dir, "loop.json", "symbolic link", options);
  }
  // io::filesIn lists only the wanted names and skips links among the others.
  const std::string dir = tmp_.file("listing");
  io::makeDirectory(dir);
  test::writeFile(dir + "/b.jpg", "x");
  test::writeFile(dir + "/a.jpg", "x");
  std::filesystem::create_symlink(dir + "/missing", dir + "/notes.txt");
  const auto jpgs = io::filesIn(dir, [](const std::string& n) { return io::endsWith(n, ".jpg"); });
  EXPECT_EQ(jpgs, (std::vector<std::string>{"a.jpg", "b.jpg"}));
  EXPECT_FALSE(io::optionalFileExists(dir + "/none.json"));
  EXPECT_TRUE(io::optionalFileExists(dir + "/a.jpg"));
  EXPECT_THROW(io::optionalFileExists(dir + "/notes.txt"), Error);
}

TEST_F(SceneImport, MapsColourLabelMapsThroughThePalette) {
  const std::string dir = copy();
  // A colour label map: building colour everywhere, black (ignore) in the first row.
  std::string out;
  const std::string py =
      "import zlib, struct, sys\n"
      "w, h = 64, 48\n"
      "rows = b''.join(b'\\x00' + (bytes([0,0,0]) * w if y == 0 else bytes([220,20,60]) * w) for y "
      "in range(h))\n"
      "c = lambda t, d: struct.pack('>I', len(d)) + t + d + struct.pack('>I', zlib.crc32(t + d))\n"
      "open(sys.argv[1], 'wb').write(b'\\x89PNG\\r\\n\\x1a\\n' + c(b'IHDR', "
      "struct.pack('>IIBBBBB', w, h, 8, 2, 0, 0, 0)) + c(b'IDAT', zlib.compress(rows)) + "
      "c(b'IEND', b''))\n";
  test::writeFile(tmp_.file("png.py"), py);
  ASSERT_EQ(
      test::runCommand(
          "/usr/bin/python3 " + tmp_.file("png.py") + " " + dir + "/labels/view_000.png", &out),
      0)
      << out;
  const io::Scene scene = io::importScene(dir);
  EXPECT_EQ(scene.views[0].labels.at(5, 0), io::kIgnoreLabel);
  EXPECT_EQ(scene.views[0].labels.at(5, 1), 2);
}

TEST_F(SceneImport, GreyAlphaLabelMapsAreClassIdsWithTransparentIgnore) {
  // fuzz/regressions/label_png/grey_alpha.png (scripts/reliability/inputs.py): grey = x * 3 / 64
  // (classes 0, 1, 2 across the image), alpha 255 for y < 40, 0 below. It was read as BGRA colours
  // and became all "ignore" without a word.
  const std::string dir = copy();
  std::filesystem::copy_file(std::string(SADSPLAT_TEST_DATA_DIR) +
                                 "/../fuzz/regressions/label_png/grey_alpha.png",
                             dir + "/labels/view_000.png",
                             std::filesystem::copy_options::overwrite_existing);
  const io::Scene scene = io::importScene(dir);
  const io::Image8& l = scene.views[0].labels;
  EXPECT_EQ(l.at(0, 0), 0);
  EXPECT_EQ(l.at(30, 10), 1);
  EXPECT_EQ(l.at(63, 39), 2);
  EXPECT_EQ(l.at(30, 40), io::kIgnoreLabel);
}

TEST_F(SceneImport, ImageHeadersAreCheckedBeforeDecoding) {
  // A 676-byte JPEG that claims 10000 x 10000 pixels (once decoded whole: 2.1-2.8 GB for 30000^2)
  // and a PNG that claims 60000 x 60000 (once OpenCV's assertion, exit 3).
  for (const char* name : {"jpeg_10000x10000_676_bytes.png", "png_60000x60000.png"}) {
    const std::string dir = copy();
    std::filesystem::copy_file(std::string(SADSPLAT_TEST_DATA_DIR) + "/../fuzz/regressions/photo/" +
                                   name,
                               dir + "/images/view_003.png",
                               std::filesystem::copy_options::overwrite_existing);
    try {
      io::importScene(dir);
      ADD_FAILURE() << name;
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), dir + "/images/view_003.png");
      EXPECT_NE(e.field().find("header size"), std::string::npos) << e.what();
    }
    std::filesystem::remove_all(dir);
  }
  // A header's size is what the decoder then gives.
  const io::ImageHeader h = io::readImageHeader(std::string(kTinyScene) + "/images/view_000.png");
  EXPECT_EQ(h.format, "png");
  EXPECT_EQ(h.width, 64u);
  EXPECT_EQ(h.height, 48u);
}

TEST_F(SceneImport, BadInputsNameTheFileAndTheField) {
  expectError(tmp_.file("nowhere"), "nowhere", "existing directory");
  {
    const std::string dir = copy();
    test::writeFile(dir + "/classes.json", "{\"classes\": [{\"name\": \"a\", \"color\": [1, 2]}]}");
    expectError(dir, "classes.json", "classes[0].color");
    test::writeFile(dir + "/classes.json", "{\"classes\": [");
    expectError(dir, "classes.json", "JSON syntax");
    test::runCommand("rm -rf '" + dir + "'");
  }
  {
    const std::string dir = copy();
    // A label id outside the 3-class list: make the classes list shorter.
    test::writeFile(dir + "/classes.json",
                    "{\"classes\": [{\"name\": \"road\", \"color\": [128, 64, 128]}]}");
    expectError(dir, "labels/view_000.png", "class id below 1");
    test::runCommand("rm -rf '" + dir + "'");
  }
  {
    const std::string dir = copy();
    auto model = io::readColmapModel(dir + "/sparse/0");
    model.cameras[0].width = 80;
    io::writeColmapText(dir + "/sparse/0", model);
    expectError(dir, "images/view_000.png", "size: expected 80x48");
    test::runCommand("rm -rf '" + dir + "'");
  }
  {
    const std::string dir = copy();
    test::runCommand("rm '" + dir + "/images/view_004.png'");
    expectError(dir, "images/view_004.png", "missing");
    test::runCommand("rm -rf '" + dir + "'");
  }
  {
    const std::string dir = copy();
    test::runCommand("rm '" + dir + "/labels/view_003.png'");
    expectError(dir, "labels/view_003.png", "label map for labelled view");
    test::runCommand("rm -rf '" + dir + "'");
  }
  {
    const std::string dir = copy();
    test::writeFile(dir + "/split.json",
                    "{\"train\": [\"view_000.png\"], \"test\": [\"nope.png\"]}");
    expectError(dir, "split.json", "nope.png");
    test::writeFile(
        dir + "/split.json",
        "{\"train\": [\"view_000.png\"], \"test\": [], \"labelled\": [\"view_001.png\"]}");
    expectError(dir, "split.json", "also in \"train\"");
    test::runCommand("rm -rf '" + dir + "'");
  }
}

}  // namespace
}  // namespace sadsplat
