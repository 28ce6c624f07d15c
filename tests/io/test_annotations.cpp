// Annotations from labelling tools: hand-written LabelMe and COCO files (polygons, rectangles,
// list and string RLE) read, rasterised into label maps on import, and every error.
#include <gtest/gtest.h>

#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/annotations.h"
#include "sadsplat/io/scene_import.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

TEST(Annotations, CocoRleDecodesColumnMajorRunsAndTheCompressedString) {
  // A 3 x 4 image (height 3): runs 2 zeros, 3 ones, 7 zeros in column-major order set the
  // pixels (x 0, y 2), (1, 0), (1, 1).
  const auto mask = io::decodeCocoRle({2, 3, 7}, 3, 4, "<test>");
  std::vector<std::uint8_t> want(12, 0);
  want[2 * 4 + 0] = want[0 * 4 + 1] = want[1 * 4 + 1] = 1;
  EXPECT_EQ(mask, want);
  // pycocotools' string form, encoded by hand from its rleToString: "237" is {2, 3, 7}; "12:O"
  // is {1, 2, 10, 1} (the 4th run stored as 1 - 2 = -1: 'O' = 48 + 31, sign bit 0x10 set).
  EXPECT_EQ(io::cocoRleCounts("237", "<test>"), (std::vector<std::uint32_t>{2, 3, 7}));
  EXPECT_EQ(io::cocoRleCounts("12:O", "<test>"), (std::vector<std::uint32_t>{1, 2, 10, 1}));
  // A value of 40 needs two characters: 40 = 8 + 1 * 32 -> '8' | 0x20 = 'X', then '1'.
  EXPECT_EQ(io::cocoRleCounts("X1", "<test>"), (std::vector<std::uint32_t>{40}));
  EXPECT_THROW(io::decodeCocoRle({2, 3, 6}, 3, 4, "<test>"), Error);   // 11 of 12 pixels
  EXPECT_THROW(io::decodeCocoRle({2, 3, 8}, 3, 4, "<test>"), Error);   // 13 of 12
  EXPECT_THROW(io::cocoRleCounts("X", "<test>"), Error);               // cut off
}

class AnnotatedImport : public ::testing::Test {
 protected:
  void SetUp() override {
    if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
    dir_ = test::copyTree(test::kTinyScene, tmp_.file("scene"));
    // The views' own label maps and split go: the annotations are the only labels.
    std::filesystem::remove_all(dir_ + "/labels");
    std::filesystem::remove(dir_ + "/split.json");
  }
  io::Scene importWith(const std::string& annotations) {
    io::ImportOptions o;
    o.annotations = annotations;
    o.test_every = 0;
    return io::importScene(dir_, o);
  }
  void expectError(const std::string& annotations, const std::string& needle) {
    try {
      importWith(annotations);
      FAIL() << "expected an error with " << needle;
    } catch (const Error& e) {
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
  test::TempDir tmp_;
  std::string dir_;
};

TEST_F(AnnotatedImport, LabelMePolygonsAndRectanglesBecomeLabelMaps) {
  // The tiny scene's views are 64 x 48. Annotated at twice that size (the original photo): the
  // coordinates are scaled. A rectangle of road over the left half, then a building triangle
  // painted over it, a line (no area, skipped).
  test::writeFile(tmp_.file("view_001.json"), R"({
    "version": "5.4.1", "imagePath": "..\\images\\view_001.png", "imageData": null,
    "imageWidth": 128, "imageHeight": 96,
    "shapes": [
      {"label": "road", "shape_type": "rectangle", "points": [[0, 0], [64, 96]], "group_id": null},
      {"label": "building", "shape_type": "polygon", "points": [[0, 0], [40, 0], [0, 40]]},
      {"label": "grass", "shape_type": "line", "points": [[100, 10], [120, 90]]}
    ]})");
  int skipped = 0;
  const auto read = io::readAnnotations(tmp_.file("view_001.json"), &skipped);
  ASSERT_EQ(read.size(), 1u);
  EXPECT_EQ(read[0].file_name, "view_001.png");
  EXPECT_EQ(read[0].shapes.size(), 2u);
  EXPECT_EQ(skipped, 1);
  const io::Scene scene = importWith(tmp_.file("view_001.json"));
  const io::View& v = scene.views[1];
  ASSERT_EQ(v.name, "view_001.png");
  ASSERT_EQ(v.labels.width, 64);
  EXPECT_TRUE(v.labelled && v.train);
  EXPECT_EQ(v.labels.at(2, 2), 2);     // building (class 2) over the road
  EXPECT_EQ(v.labels.at(25, 40), 0);   // road
  EXPECT_EQ(v.labels.at(31, 10), 0);   // road, left of x = 32
  EXPECT_EQ(v.labels.at(33, 10), io::kIgnoreLabel);  // right half: not annotated
  EXPECT_EQ(v.labels.at(60, 30), io::kIgnoreLabel);  // the line labels nothing
  // The other views have no labels.
  EXPECT_TRUE(scene.views[0].labels.empty());
  EXPECT_FALSE(scene.views[0].labelled);
}

TEST_F(AnnotatedImport, CocoPolygonsAndMasksBecomeLabelMaps) {
  // view_000: a grass polygon; view_003: a road mask (RLE list: the first 10 columns of 48 rows
  // then nothing) and a building polygon painted after it.
  test::writeFile(tmp_.file("coco.json"), R"({
    "images": [{"id": 7, "file_name": "images/view_000.png", "width": 64, "height": 48},
               {"id": 9, "file_name": "view_003.png", "width": 64, "height": 48}],
    "categories": [{"id": 1, "name": "road"}, {"id": 2, "name": "grass"}, {"id": 3, "name": "building"}],
    "annotations": [
      {"id": 1, "image_id": 7, "category_id": 2, "iscrowd": 0,
       "segmentation": [[10, 10, 30, 10, 30, 30, 10, 30]]},
      {"id": 2, "image_id": 9, "category_id": 1, "iscrowd": 1,
       "segmentation": {"size": [48, 64], "counts": [0, 480, 2592]}},
      {"id": 3, "image_id": 9, "category_id": 3, "iscrowd": 0,
       "segmentation": [[0, 0, 5, 0, 5, 5, 0, 5]]}
    ]})");
  const io::Scene scene = importWith(tmp_.file("coco.json"));
  const io::View& a = scene.views[0];
  EXPECT_EQ(a.labels.at(20, 20), 1);  // grass
  EXPECT_EQ(a.labels.at(5, 5), io::kIgnoreLabel);
  const io::View& b = scene.views[3];
  ASSERT_EQ(b.name, "view_003.png");
  EXPECT_EQ(b.labels.at(9, 40), 0);   // road: columns 0..9
  EXPECT_EQ(b.labels.at(10, 40), io::kIgnoreLabel);
  EXPECT_EQ(b.labels.at(2, 2), 2);    // the building over the road
}

TEST_F(AnnotatedImport, BadAnnotationsAreOneLineErrors) {
  const auto labelme = [&](const std::string& name, const std::string& image, int w,
                           const std::string& shapes) {
    test::writeFile(tmp_.file(name), "{\"imagePath\": \"" + image + "\", \"imageWidth\": " +
                                         std::to_string(w) + ", \"imageHeight\": 48, \"shapes\": [" +
                                         shapes + "]}");
    return tmp_.file(name);
  };
  const std::string tri = R"({"label": "road", "shape_type": "polygon", "points": [[0,0],[9,0],[0,9]]})";
  expectError(labelme("a.json", "nowhere.png", 64, tri), "nowhere.png");
  expectError(labelme("b.json", "view_000.png", 64,
                      R"({"label": "lake", "points": [[0,0],[9,0],[0,9]]})"),
              "lake");
  expectError(labelme("c.json", "view_000.png", 64,
                      R"({"label": "road", "points": [[0,0],[9,0]]})"),
              "at least 3 points");
  expectError(labelme("d.json", "view_000.png", 100, tri), "aspect ratio");
  test::writeFile(tmp_.file("e.json"), "{\"shapes\": ");
  expectError(tmp_.file("e.json"), "JSON syntax");
  test::writeFile(tmp_.file("f.json"), "[1, 2]");
  expectError(tmp_.file("f.json"), "LabelMe");
  test::writeFile(tmp_.file("g.json"), R"({"images": [{"id": 1, "file_name": "view_000.png",
    "width": 64, "height": 48}], "categories": [{"id": 1, "name": "road"}],
    "annotations": [{"image_id": 1, "category_id": 5, "segmentation": [[0,0,9,0,0,9]]}]})");
  expectError(tmp_.file("g.json"), "category_id");
  expectError(tmp_.file("missing.json"), "missing.json");
  // A view with both a label map and an annotation.
  std::filesystem::create_directories(dir_ + "/labels");
  std::filesystem::copy_file(std::string(test::kTinyScene) + "/labels/view_000.png",
                             dir_ + "/labels/view_000.png");
  expectError(labelme("h.json", "view_000.png", 64, tri), "one source of labels");
  // Annotations need the class list.
  std::filesystem::remove_all(dir_ + "/labels");
  std::filesystem::remove(dir_ + "/classes.json");
  expectError(labelme("i.json", "view_000.png", 64, tri), "classes.json");
}

TEST_F(AnnotatedImport, ShapesFarBeyondTheImageAreClippedNotWrapped) {
  // A rectangle drawn far past the photo's corners covers all of it (clipped to the image before
  // OpenCV's fixed-point coordinates; it once wrapped and labelled one pixel), and a triangle
  // with a vertex 5 million pixels away still labels the part of the photo it covers.
  test::writeFile(tmp_.file("far.json"), R"({"imagePath": "view_002.png", "imageWidth": 64,
    "imageHeight": 48, "shapes": [
      {"label": "grass", "shape_type": "rectangle", "points": [[-50000, -50000], [90000, 90000]]},
      {"label": "building", "points": [[0, 0], [5000000, 0], [0, 24]]}]})");
  const io::Scene scene = importWith(tmp_.file("far.json"));
  const io::View& v = scene.views[2];
  ASSERT_EQ(v.labels.width, 64);
  std::size_t grass = 0, building = 0;
  for (int y = 0; y < 48; ++y) {
    for (int x = 0; x < 64; ++x) {
      grass += v.labels.at(x, y) == 1;
      building += v.labels.at(x, y) == 2;
    }
  }
  EXPECT_EQ(grass + building, 64u * 48u);  // every pixel labelled
  EXPECT_EQ(v.labels.at(63, 47), 1);
  EXPECT_EQ(v.labels.at(63, 5), 2);   // the triangle's long edge falls ~0.0003 px per px
  EXPECT_EQ(v.labels.at(10, 30), 1);
}

TEST_F(AnnotatedImport, ValuesOfTheWrongTypeOrRangeNameTheirField) {
  const auto write = [&](const std::string& name, const std::string& json) {
    test::writeFile(tmp_.file(name), json);
    return tmp_.file(name);
  };
  const std::string image = R"({"id": 1, "file_name": "view_000.png", "width": 64, "height": 48})";
  const std::string cats = R"([{"id": 1, "name": "road"}])";
  // Two images with one id would draw one photo's annotations on the other.
  expectError(write("dup.json", "{\"images\": [" + image + R"(, {"id": 1, "file_name":
      "view_001.png", "width": 64, "height": 48}], "categories": )" + cats +
                                    ", \"annotations\": []}"),
              "images[1].id: expected an id no other image has");
  expectError(write("noid.json", "{\"images\": [" + image + "], \"categories\": " + cats +
                                     R"(, "annotations": [{"image_id": 1, "segmentation": []}]})"),
              "annotations[0].category_id: expected a value, got missing");
  expectError(write("str.json", "{\"images\": [" + image + "], \"categories\": " + cats +
                                    R"(, "annotations": ["road"]})"),
              "annotations[0]: expected an object");
  expectError(write("wrap.json", "{\"images\": [" + image + "], \"categories\": " + cats +
                                     R"(, "annotations": [{"image_id": 1, "category_id": 1,
      "segmentation": {"size": [48, 64], "counts": [4294967296, 3072]}}]})"),
              "counts[0]: expected an integer in [0, 3072]");
  expectError(write("type.json", R"({"imagePath": "view_000.png", "imageWidth": 64,
      "imageHeight": 48, "shapes": [{"label": "road", "shape_type": 7, "points": []}]})"),
              "shapes[0].shape_type: expected a string, got 7");
  expectError(write("huge.json", R"({"imagePath": "view_000.png", "imageWidth": 64,
      "imageHeight": 48, "shapes": [{"label": "road", "points": [[0, 0], [1e308, 0], [0, 9]]}]})"),
              "shapes[0].points[1][0]: expected a number in [");
  expectError(write("big.json", "{\"shapes\": [], \"imagePath\": \"view_000.png\", "
                                "\"imageWidth\": 1e400, \"imageHeight\": 48}"),
              "JSON syntax");
}

TEST_F(AnnotatedImport, ScenesWithoutClassesOrSplitAndTheUndistortersLayout) {
  // No classes.json, no labels: a plain 3DGS scene. No split.json: every 8th view is a test view
  // (the tiny scene's 8 views are fewer than 2 x 8: all train).
  std::filesystem::remove(dir_ + "/classes.json");
  io::Scene scene = io::importScene(dir_);
  EXPECT_TRUE(scene.classes.empty());
  for (const auto& v : scene.views) EXPECT_TRUE(v.train && !v.test && v.labels.empty());
  io::ImportOptions every4;
  every4.test_every = 4;
  scene = io::importScene(dir_, every4);
  EXPECT_TRUE(scene.views[0].test && !scene.views[0].train);
  EXPECT_TRUE(scene.views[4].test);
  EXPECT_TRUE(scene.views[1].train && !scene.views[1].test);
  // COLMAP's image_undistorter writes sparse/ itself: read as sparse/0.
  std::filesystem::rename(dir_ + "/sparse/0", dir_ + "/sparse_0");
  std::filesystem::remove_all(dir_ + "/sparse");
  std::filesystem::rename(dir_ + "/sparse_0", dir_ + "/sparse");
  EXPECT_EQ(io::importScene(dir_).views.size(), 8u);
  std::filesystem::remove_all(dir_ + "/sparse");
  try {
    io::importScene(dir_);
    FAIL();
  } catch (const Error& e) {
    EXPECT_NE(std::string(e.what()).find("sadsplat sfm"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace sadsplat
