// The frame of `convert` / `extract` LAS exports of a run without a georeference
// (pipeline/las_frame.h): the maps' local metres, z up, from the scene the run trained on — here a
// scene whose up is +y, so the frame is not the scene's own axes; without a run or its scene, the
// scene's axes with a note.
#include <gtest/gtest.h>

#include <cmath>
#include <sstream>

#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/geo/las_export.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/las.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/pipeline/las_frame.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

// Two cameras looking along -y (the scene's up is +y), 8 x 8 grey images.
io::Scene lookingAlongMinusY() {
  io::Scene s;
  gaussians::RasterCamera r;
  r.setRotation({1, 0, 0, 0, 0, 1, 0, -1, 0});  // camera z = world -y
  for (int i = 0; i < 2; ++i) {
    io::View v;
    v.name = "v" + std::to_string(i) + ".png";
    v.camera.width = v.camera.height = 8;
    v.camera.fx = v.camera.fy = 8;
    v.camera.cx = v.camera.cy = 4;
    v.camera.qvec = r.qvec;
    v.camera.tvec = {-10.0 * i, 0, 100};  // centre (10 i, 100, 0)
    v.rgb = {8, 8, 3, std::vector<std::uint8_t>(8 * 8 * 3, 128)};
    v.mask = {8, 8, 1, std::vector<std::uint8_t>(8 * 8, 255)};
    v.train = true;
    s.views.push_back(v);
  }
  s.classes = {{"road", {128, 128, 128}}, {"building", {200, 0, 0}}};
  return s;
}

pcl::PointCloud<GaussianPoint> someGaussians() {
  pcl::PointCloud<GaussianPoint> c;
  for (int i = 0; i < 5; ++i) {
    GaussianPoint p;
    p.x = 3.0f * i;
    p.y = 1.5f * i - 2;
    p.z = 7.0f - 2.0f * i;
    p.label = i % 2;
    c.push_back(p);
  }
  return c;
}

TEST(LasFrame, ARunWithoutAGeoreferenceWritesTheMapsLocalFrameZUp) {
  test::TempDir dir;
  io::writeSceneCache(dir.file("scene.cache"), lookingAlongMinusY());
  const std::string run = dir.file("run");
  io::makeDirectory(run);
  io::RunRecord record;
  record.scene = dir.file("scene.cache");
  io::RunDirectory(run).writeRecord(record);
  const pcl::PointCloud<GaussianPoint> model = someGaussians();
  io::writeGaussians(run + "/model.ply", model);

  std::ostringstream notes;
  const geo::LasExportOptions options =
      pipeline::lasOptionsForModel(run + "/model.ply", "", &notes);
  ASSERT_TRUE(options.local_frame.has_value());
  EXPECT_TRUE(notes.str().empty()) << notes.str();
  const std::string summary = geo::writeGaussiansLas(dir.file("m.las"), model, options);
  EXPECT_NE(summary.find("local metres of the map"), std::string::npos) << summary;
  const std::vector<io::LasPoint> points = io::readLas(dir.file("m.las"));
  ASSERT_EQ(points.size(), model.size());
  // Up is the scene's +y, east' its x; north' = up x east' = -z: (x, y, z) -> (x, -z, y).
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(points[i].x, model[i].x, 2e-3) << i;
    EXPECT_NEAR(points[i].y, -model[i].z, 2e-3) << i;
    EXPECT_NEAR(points[i].z, model[i].y, 2e-3) << i;
  }
  // The run directory itself gives the same.
  EXPECT_TRUE(pipeline::lasOptionsForModel(run, "", nullptr).local_frame.has_value());
}

TEST(LasFrame, WithoutARunOrItsSceneThePointsKeepTheScenesAxesWithANote) {
  test::TempDir dir;
  const pcl::PointCloud<GaussianPoint> model = someGaussians();
  io::writeGaussians(dir.file("alone.ply"), model);
  std::ostringstream notes;
  geo::LasExportOptions options = pipeline::lasOptionsForModel(dir.file("alone.ply"), "", &notes);
  EXPECT_FALSE(options.local_frame.has_value());
  EXPECT_NE(notes.str().find("no run.json beside"), std::string::npos) << notes.str();
  EXPECT_NE(notes.str().find("scene's own axes"), std::string::npos) << notes.str();
  geo::writeGaussiansLas(dir.file("a.las"), model, options);
  const std::vector<io::LasPoint> points = io::readLas(dir.file("a.las"));
  ASSERT_EQ(points.size(), model.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    EXPECT_NEAR(points[i].z, model[i].z, 2e-3) << i;
  }

  const std::string run = dir.file("run");
  io::makeDirectory(run);
  io::RunRecord record;
  record.scene = dir.file("gone.cache");
  io::RunDirectory(run).writeRecord(record);
  io::writeGaussians(run + "/model.ply", model);
  notes.str("");
  options = pipeline::lasOptionsForModel(run + "/model.ply", "", &notes);
  EXPECT_FALSE(options.local_frame.has_value());
  EXPECT_NE(notes.str().find("gone.cache"), std::string::npos) << notes.str();
}

}  // namespace
}  // namespace sadsplat
