// transforms.json (nerfstudio, instant-ngp): axes, intrinsics, distortion models, the import of a
// whole scene in that format, and the errors.
#include <gtest/gtest.h>

#include <Eigen/Geometry>
#include <nlohmann/json.hpp>

#include <cmath>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/io/semantic_ply.h"
#include "sadsplat/io/transforms_json.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using nlohmann::json;

std::array<int, 2> noImageSize(const std::string& path) {
  ADD_FAILURE() << "the size of " << path << " was asked although the file gives w and h";
  return {1, 1};
}

// Pixel of a world point through a COLMAP image and its pinhole camera (no distortion).
Eigen::Vector2d project(const io::ColmapImage& im, const io::ColmapCamera& cam,
                        const Eigen::Vector3d& world, double* depth = nullptr) {
  const Eigen::Quaterniond q(im.qvec[0], im.qvec[1], im.qvec[2], im.qvec[3]);
  const Eigen::Vector3d x =
      q.normalized() * world + Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]);
  if (depth) *depth = x.z();
  const double fx = cam.params[0], fy = cam.params[1], cx = cam.params[2], cy = cam.params[3];
  return {fx * x.x() / x.z() + cx, fy * x.y() / x.z() + cy};
}

class TransformsJson : public ::testing::Test {
 protected:
  std::string write(const json& j, const std::string& name = "transforms.json") {
    test::writeFile(tmp_.file(name), j.dump(2));
    return tmp_.file(name);
  }
  void expectError(const json& j, const std::string& needle) {
    const std::string path = write(j);
    try {
      io::readTransformsJson(path, noImageSize);
      FAIL() << "expected an error containing " << needle;
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), path);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  }
  static json frame(const std::string& file, const Eigen::Matrix4d& c2w) {
    json m = json::array();
    for (int i = 0; i < 4; ++i) m.push_back({c2w(i, 0), c2w(i, 1), c2w(i, 2), c2w(i, 3)});
    return {{"file_path", file}, {"transform_matrix", m}};
  }
  test::TempDir tmp_;
};

// The spec's axes, worked by hand: a camera 10 m above the origin with the identity rotation
// looks down (-z in OpenGL); +x is right and +y is up in the image.
TEST_F(TransformsJson, OpenGlCameraAxesBecomeColmapsWorldToCamera) {
  Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
  c2w(2, 3) = 10;
  const json j = {{"fl_x", 100},
                  {"fl_y", 100},
                  {"cx", 100},
                  {"cy", 50},
                  {"w", 200},
                  {"h", 100},
                  {"frames", json::array({frame("images/a.jpg", c2w)})}};
  const io::TransformsJson t = io::readTransformsJson(write(j), noImageSize);
  ASSERT_EQ(t.model.images.size(), 1u);
  ASSERT_EQ(t.model.cameras.size(), 1u);
  EXPECT_EQ(t.model.cameras[0].model, io::CameraModel::kPinhole);
  EXPECT_EQ(t.model.images[0].name, "a.jpg");
  EXPECT_EQ(t.image_dir, tmp_.path() + "/images");
  double depth = 0;
  const auto origin = project(t.model.images[0], t.model.cameras[0], {0, 0, 0}, &depth);
  EXPECT_NEAR(depth, 10, 1e-12);
  EXPECT_NEAR(origin.x(), 100, 1e-9);
  EXPECT_NEAR(origin.y(), 50, 1e-9);
  const auto right = project(t.model.images[0], t.model.cameras[0], {1, 0, 0});
  EXPECT_NEAR(right.x(), 110, 1e-9);
  EXPECT_NEAR(right.y(), 50, 1e-9);
  const auto up = project(t.model.images[0], t.model.cameras[0], {0, 1, 0});
  EXPECT_NEAR(up.x(), 100, 1e-9);
  EXPECT_NEAR(up.y(), 40, 1e-9);  // world +y is up in the picture: a smaller row
}

TEST_F(TransformsJson, FieldOfViewPerFrameIntrinsicsAndDistortionModels) {
  const Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  json f1 = frame("one.png", I), f2 = frame("two.png", I), f3 = frame("three.png", I),
       f4 = frame("four.png", I);
  f2["fl_x"] = 300;  // a frame's own intrinsics win over the file's
  f3["k1"] = 0.1;
  f3["k3"] = 0.01;
  f4["camera_model"] = "OPENCV_FISHEYE";
  f4["k1"] = 0.2;
  f4["k4"] = 0.001;
  const json j = {
      {"camera_angle_x", 2 * std::atan(0.5)}, {"w", 200}, {"h", 100}, {"frames", {f1, f2, f3, f4}}};
  const io::TransformsJson t = io::readTransformsJson(write(j), noImageSize);
  EXPECT_EQ(t.image_dir, tmp_.path());
  ASSERT_EQ(t.model.cameras.size(), 4u);
  const auto& c1 = t.model.cameras[0];
  EXPECT_EQ(c1.model, io::CameraModel::kPinhole);
  EXPECT_NEAR(c1.params[0], 200, 1e-9);  // 0.5 w / tan(angle / 2)
  EXPECT_NEAR(c1.params[1], 200, 1e-9);
  EXPECT_DOUBLE_EQ(c1.params[2], 100);  // default principal point: the image centre
  EXPECT_DOUBLE_EQ(c1.params[3], 50);
  EXPECT_DOUBLE_EQ(t.model.cameras[1].params[0], 300);
  EXPECT_DOUBLE_EQ(t.model.cameras[1].params[1], 300);  // fl_y defaults to fl_x
  EXPECT_EQ(t.model.cameras[2].model, io::CameraModel::kFullOpenCV);
  EXPECT_DOUBLE_EQ(t.model.cameras[2].params[4], 0.1);
  EXPECT_DOUBLE_EQ(t.model.cameras[2].params[8], 0.01);
  EXPECT_EQ(t.model.cameras[3].model, io::CameraModel::kOpenCVFisheye);
  EXPECT_DOUBLE_EQ(t.model.cameras[3].params[4], 0.2);
  EXPECT_DOUBLE_EQ(t.model.cameras[3].params[7], 0.001);
  // Frames sharing intrinsics share a camera.
  const json shared = {
      {"fl_x", 50}, {"w", 20}, {"h", 10}, {"frames", {frame("a.png", I), frame("b.png", I)}}};
  EXPECT_EQ(io::readTransformsJson(write(shared), noImageSize).model.cameras.size(), 1u);
}

TEST_F(TransformsJson, ImageSizesComeFromTheImagesWhenTheFileHasNone) {
  // The NeRF synthetic layout: "./train/r_0" without an extension, camera_angle_x only.
  std::filesystem::create_directories(tmp_.file("train"));
  test::writeFile(tmp_.file("train/r_0.png"), "not read by this test");
  const json j = {{"camera_angle_x", 0.69},
                  {"frames", json::array({frame("./train/r_0", Eigen::Matrix4d::Identity())})}};
  std::string asked;
  const auto t = io::readTransformsJson(write(j), [&](const std::string& path) {
    asked = path;
    return std::array<int, 2>{800, 600};
  });
  EXPECT_EQ(asked, tmp_.path() + "/train/r_0.png");
  EXPECT_EQ(t.model.images[0].name, "train/r_0.png");
  EXPECT_EQ(t.model.cameras[0].width, 800u);
  EXPECT_EQ(t.model.cameras[0].height, 600u);
}

// nerfstudio's per-frame mask_path: relative to the file, kept per image for the import.
TEST_F(TransformsJson, MaskPathsAreKeptPerImage) {
  const Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  json a = frame("images/a.png", I), b = frame("images/b.png", I);
  a["mask_path"] = "masks/a.png";
  const json j = {{"fl_x", 100}, {"w", 200}, {"h", 100}, {"frames", json::array({a, b})}};
  const io::TransformsJson t = io::readTransformsJson(write(j), noImageSize);
  ASSERT_EQ(t.mask_paths.size(), 1u);
  EXPECT_EQ(t.mask_paths.at("a.png"), tmp_.path() + "/masks/a.png");
}

TEST_F(TransformsJson, BadFilesAreOneLineErrors) {
  const Eigen::Matrix4d I = Eigen::Matrix4d::Identity();
  const json base = {{"fl_x", 100}, {"w", 200}, {"h", 100}};
  auto with = [&](const json& frames) {
    json j = base;
    j["frames"] = frames;
    return j;
  };
  expectError(json{{"fl_x", 1}}, "frames");
  expectError(with(json::array()), "at least one frame");
  Eigen::Matrix4d scaled = I;
  scaled(0, 0) = 2;  // a scale hidden in the rotation
  expectError(with(json::array({frame("a.png", scaled)})), "a rotation");
  Eigen::Matrix4d mirrored = I;
  mirrored(0, 0) = -1;
  expectError(with(json::array({frame("a.png", mirrored)})), "det");
  json no_matrix = {{"file_path", "a.png"}};
  expectError(with(json::array({no_matrix})), "transform_matrix");
  expectError(with(json::array({frame("a.png", I), frame("./a.png", I)})), "each image once");
  expectError(with(json::array({frame("/abs/a.png", I)})), "relative");
  json fisheye_tangential = frame("a.png", I);
  fisheye_tangential["camera_model"] = "OPENCV_FISHEYE";
  fisheye_tangential["p1"] = 0.1;
  expectError(with(json::array({fisheye_tangential})), "p1");
  json k4 = frame("a.png", I);
  k4["k4"] = 0.1;
  expectError(with(json::array({k4})), "k4");
  json equirect = frame("a.png", I);
  equirect["camera_model"] = "EQUIRECTANGULAR";
  expectError(with(json::array({equirect})), "OPENCV or OPENCV_FISHEYE");
  json nan_focal = with(json::array({frame("a.png", I)}));
  nan_focal["fl_x"] = "wide";
  expectError(nan_focal, "fl_x");
  expectError(json{{"w", 200}, {"h", 100}, {"frames", json::array({frame("a.png", I)})}},
              "focal length");
  json bad_mask = frame("a.png", I);
  bad_mask["mask_path"] = 3;
  expectError(with(json::array({bad_mask})), "mask_path");
  bad_mask["mask_path"] = "/abs/mask.png";
  expectError(with(json::array({bad_mask})), "mask_path");
  test::writeFile(tmp_.file("broken.json"), "{\"frames\": [");
  EXPECT_THROW(io::readTransformsJson(tmp_.file("broken.json"), noImageSize), Error);
}

// The fixture scene written as nerfstudio writes a COLMAP project (camera-to-world with the y and
// z columns negated, images in images/, the points as sparse_pc.ply) imports to the same views.
TEST_F(TransformsJson, TheFixtureSceneAsTransformsJsonImportsLikeItsColmapModel) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  const std::string dir = test::copyTree(test::kTinyScene, tmp_.file("scene"));
  const io::ColmapModel colmap = io::readColmapModel(dir + "/sparse/0");
  json frames = json::array();
  for (const auto& im : colmap.images) {
    const auto& cam = colmap.cameras[0];
    ASSERT_EQ(cam.model, io::CameraModel::kPinhole);
    const Eigen::Quaterniond q(im.qvec[0], im.qvec[1], im.qvec[2], im.qvec[3]);
    const Eigen::Matrix3d w2c = q.normalized().toRotationMatrix();
    Eigen::Matrix4d c2w = Eigen::Matrix4d::Identity();
    c2w.topLeftCorner<3, 3>() = w2c.transpose();
    c2w.topRightCorner<3, 1>() =
        -w2c.transpose() * Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]);
    c2w.col(1) *= -1;
    c2w.col(2) *= -1;
    json f = frame("images/" + im.name, c2w);
    f["fl_x"] = cam.params[0];
    f["fl_y"] = cam.params[1];
    f["cx"] = cam.params[2];
    f["cy"] = cam.params[3];
    f["w"] = cam.width;
    f["h"] = cam.height;
    frames.push_back(f);
  }
  pcl::PointCloud<pcl::PointXYZRGBL> points;
  for (const auto& p : colmap.points) {
    pcl::PointXYZRGBL x;
    x.x = float(p.xyz[0]), x.y = float(p.xyz[1]), x.z = float(p.xyz[2]);
    x.r = p.rgb[0], x.g = p.rgb[1], x.b = p.rgb[2];
    x.label = 0;
    points.push_back(x);
  }
  io::writeSemanticPly(dir + "/sparse_pc.ply", points);
  test::writeFile(
      dir + "/transforms.json",
      json{{"camera_model", "OPENCV"}, {"frames", frames}, {"ply_file_path", "sparse_pc.ply"}}
          .dump());
  const io::Scene reference = io::importScene(dir);
  std::filesystem::remove_all(dir + "/sparse");
  const io::Scene scene = io::importScene(dir);
  ASSERT_EQ(scene.views.size(), reference.views.size());
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    const auto& a = scene.views[i];
    const auto& b = reference.views[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.train, b.train);
    EXPECT_EQ(a.labelled, b.labelled);
    EXPECT_EQ(a.rgb.pixels, b.rgb.pixels);
    EXPECT_EQ(a.labels.pixels, b.labels.pixels);  // labels/<stem>.png found as in COLMAP scenes
    EXPECT_DOUBLE_EQ(a.camera.fx, b.camera.fx);
    const auto ra = a.camera.rotation(), rb = b.camera.rotation();
    for (int k = 0; k < 9; ++k) EXPECT_NEAR(ra[k], rb[k], 1e-12) << a.name;
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(a.camera.tvec[k], b.camera.tvec[k], 1e-9) << a.name;
  }
  ASSERT_EQ(scene.points.size(), reference.points.size());
  EXPECT_EQ(scene.points[7].xyz, reference.points[7].xyz);
  EXPECT_EQ(scene.points[7].rgb, reference.points[7].rgb);
}

}  // namespace
}  // namespace sadsplat
