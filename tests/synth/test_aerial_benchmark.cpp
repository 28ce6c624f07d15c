// The procedural benchmark: determinism, exact geometry, label/depth/point consistency through the
// written files, and the scene import of what it writes.
#include <gtest/gtest.h>

#include <set>

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/colmap.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/synth/aerial_benchmark.h"
#include "sadsplat/synth/scene_writer.h"
#include "sadsplat/synth/world.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {
namespace fs = std::filesystem;

synth::SynthOptions small(synth::SceneKind kind, std::uint64_t seed) {
  synth::SynthOptions o;
  o.kind = kind;
  o.seed = seed;
  o.views = 10;
  o.width = 96;
  o.height = 54;
  o.max_points = 400;
  o.labelled = {0, 7};
  o.test = {3, 6};
  return o;
}

// Depth map from a written .npy file (float32, H x W).
std::vector<float> readNpy(const std::string& path, int* height, int* width) {
  const std::string bytes = test::readFile(path);
  EXPECT_EQ(bytes.compare(0, 6, "\x93NUMPY"), 0);
  std::uint16_t len = 0;
  std::memcpy(&len, bytes.data() + 8, 2);
  const std::string header = bytes.substr(10, len);
  const auto open = header.find("'shape': (");
  *height = std::stoi(header.substr(open + 10));
  *width = std::stoi(header.substr(header.find(", ", open + 10) + 2));
  std::vector<float> data(static_cast<std::size_t>(*height) * *width);
  std::memcpy(data.data(), bytes.data() + 10 + len, data.size() * 4);
  return data;
}

TEST(AerialBenchmark, IsDeterministicAndIndependentOfThreads) {
  auto o = small(synth::SceneKind::kCity, 3);
  o.threads = 1;
  const auto a = synth::generate(o);
  o.threads = 2;
  const auto b = synth::generate(o);
  ASSERT_EQ(a.views.size(), b.views.size());
  for (std::size_t i = 0; i < a.views.size(); ++i) {
    EXPECT_EQ(a.views[i].rgb.pixels, b.views[i].rgb.pixels);
    EXPECT_EQ(a.views[i].labels.pixels, b.views[i].labels.pixels);
    EXPECT_EQ(a.views[i].depth, b.views[i].depth);
  }
  ASSERT_EQ(a.points.size(), b.points.size());
  test::TempDir d1, d2;
  synth::writeScene(a, d1.file("s"));
  synth::writeScene(b, d2.file("s"));
  std::string listing;
  ASSERT_EQ(test::runCommand("cd '" + d1.file("s") + "' && find . -type f | sort", &listing), 0);
  std::istringstream files(listing);
  std::string f;
  int compared = 0;
  while (std::getline(files, f)) {
    EXPECT_EQ(test::readFile(d1.file("s/" + f)), test::readFile(d2.file("s/" + f))) << f;
    ++compared;
  }
  EXPECT_GE(compared, 10 * 3 + 5);  // images, labels, depth per view + model, classes, split
  // A different seed gives a different scene.
  const auto c = synth::generate(small(synth::SceneKind::kCity, 4));
  EXPECT_NE(a.views[0].rgb.pixels, c.views[0].rgb.pixels);
}

TEST(AerialBenchmark, RaysHitTheGroundAndObjectsExactly) {
  const synth::World world(synth::SceneKind::kPort, 1);
  // Outside the labelled area: plain ground at z = 0, label 255.
  const float o[3] = {world.extent() + 20.f, 5.f, 50.f}, down[3] = {0.f, 0.f, -1.f};
  synth::Hit hit;
  ASSERT_TRUE(world.trace(o, down, 1e4f, &hit));
  EXPECT_FLOAT_EQ(hit.t, 50.f);
  EXPECT_EQ(hit.cls, 255);
  // Straight down onto the top of the tallest object.
  int tallest = 0;
  for (int i = 0; i < static_cast<int>(world.objects().size()); ++i) {
    if (world.objects()[i].hi[2] > world.objects()[tallest].hi[2]) tallest = i;
  }
  const auto& ob = world.objects()[tallest];
  const float top[3] = {0.5f * (ob.lo[0] + ob.hi[0]), 0.5f * (ob.lo[1] + ob.hi[1]),
                        ob.hi[2] + 10.f};
  ASSERT_TRUE(world.trace(top, down, 1e4f, &hit));
  EXPECT_NEAR(hit.t, 10.f, 1e-3f);
  EXPECT_EQ(hit.cls, ob.cls);
  EXPECT_FLOAT_EQ(hit.n[2], ob.shape == synth::Object::kBox ? 1.f : hit.n[2]);
  // Upwards from above everything: sky.
  const float up[3] = {0.f, 0.f, 1.f};
  EXPECT_FALSE(world.trace(top, up, 1e4f, &hit));
}

TEST(AerialBenchmark, TheNearestTrueSurfaceOfAPointIsTheOneATraceFinds) {
  // The 3D truth of `eval --3d`: 0.25 m above the top of every box taller than 3 m, the nearest
  // surface is that roof (the trace down from above agrees); 1.5 m above open ground, the ground.
  const synth::World world(synth::SceneKind::kCity, 7);
  const float down[3] = {0.f, 0.f, -1.f};
  int boxes = 0, roofs = 0;
  for (int i = 0; i < static_cast<int>(world.objects().size()); ++i) {
    const synth::Object& ob = world.objects()[i];
    if (ob.shape != synth::Object::kBox || ob.hi[2] < 3.f) continue;
    const float p[3] = {0.5f * (ob.lo[0] + ob.hi[0]), 0.5f * (ob.lo[1] + ob.hi[1]), ob.hi[2] + 0.25f};
    synth::Hit hit;
    ASSERT_TRUE(world.trace(p, down, 1e4f, &hit));
    if (hit.t > 0.2501f) continue;  // something else sits on top of this box
    const synth::NearestSurface s = world.nearestSurface(p);
    // Never farther than the roof below; nearer only where another object's side is closer
    // (a narrow box beside a taller one).
    EXPECT_LE(s.distance, 0.25f + 1e-4f) << i;
    if (std::fabs(s.distance - 0.25f) < 1e-4f) {
      EXPECT_EQ(s.cls, hit.cls) << i;
      ++roofs;
    }
    ++boxes;
  }
  EXPECT_GE(boxes, 10);
  EXPECT_GE(roofs, boxes * 3 / 4) << boxes;
  // Open ground: find a point with nothing within 3 m.
  for (float x = -world.extent() + 2; x < world.extent(); x += 3.7f) {
    const float p[3] = {x, 0.3f * x, 1.5f};
    synth::Hit hit;
    const float top[3] = {p[0], p[1], world.maxHeight() + 5};
    if (!world.trace(top, down, 1e4f, &hit) || hit.object != -1) continue;
    const synth::NearestSurface s = world.nearestSurface(p);
    if (s.object != -1) continue;  // an object's side nearer than the ground
    EXPECT_FLOAT_EQ(s.distance, 1.5f);
    EXPECT_EQ(s.cls, hit.cls);
  }
  // Inside a box: the nearest face.
  const synth::Object& ob = world.objects().front();
  const float inside[3] = {ob.lo[0] + 0.1f, 0.5f * (ob.lo[1] + ob.hi[1]), 0.5f * ob.hi[2]};
  if (ob.shape == synth::Object::kBox && ob.hi[0] - ob.lo[0] > 0.3f) {
    EXPECT_LE(world.nearestSurface(inside).distance, 0.1f + 1e-4f);
  }
}

TEST(AerialBenchmark, GroundFootprintsAreTheStandingBuildings) {
  // A city's buildings (class 0) stand on the ground in separate lots: footprints do not
  // overlap; the rooftop structures are not objects of their own; every footprint's centre lies
  // in the labelled area and the trace down onto it hits a building.
  const synth::World world(synth::SceneKind::kCity, 7);
  const auto footprints = synth::groundFootprints(world, 0);
  ASSERT_GE(footprints.size(), 10u);
  int rooftops = 0;
  for (const synth::Object& ob : world.objects()) rooftops += ob.cls == 0 && ob.lo[2] > 0.01f;
  EXPECT_GT(rooftops, 0);
  const float down[3] = {0.f, 0.f, -1.f};
  for (std::size_t i = 0; i < footprints.size(); ++i) {
    const synth::ObjectFootprint& f = footprints[i];
    EXPECT_EQ(world.objects()[f.object].cls, 0);
    EXPECT_EQ(world.objects()[f.object].lo[2], 0.f);
    const float top[3] = {0.5f * (f.x0 + f.x1), 0.5f * (f.y0 + f.y1), world.maxHeight() + 5};
    synth::Hit hit;
    ASSERT_TRUE(world.trace(top, down, 1e4f, &hit));
    EXPECT_EQ(hit.cls, 0) << i;
    for (std::size_t k = i + 1; k < footprints.size(); ++k) {
      const synth::ObjectFootprint& g = footprints[k];
      EXPECT_TRUE(f.x1 <= g.x0 || g.x1 <= f.x0 || f.y1 <= g.y0 || g.y1 <= f.y0) << i << " " << k;
    }
  }
}

TEST(AerialBenchmark, SparsePointsProjectOntoTheirSurfaceInTheWrittenFiles) {
  const auto scene = synth::generate(small(synth::SceneKind::kCountry, 2));
  ASSERT_GE(scene.points.size(), 200u);
  test::TempDir dir;
  synth::writeScene(scene, dir.file("s"));
  // Read back only what was written: COLMAP model and depth/label files.
  const auto model = io::readColmapModel(dir.file("s/sparse/0"));
  ASSERT_EQ(model.points.size(), scene.points.size());
  ASSERT_EQ(model.images.size(), scene.views.size());
  const auto& cam = model.cameras[0].params;  // fx fy cx cy
  int checked = 0, label_agree = 0;
  for (std::size_t k = 0; k < model.points.size(); ++k) {
    const auto& p = model.points[k];
    ASSERT_GE(p.track.size(), 2u);
    for (const auto& [image_id, idx] : p.track) {
      const auto& im = model.images[image_id - 1];
      const double w = im.qvec[0], x = im.qvec[1], y = im.qvec[2], z = im.qvec[3];
      const double R[9] = {
          1 - 2 * (y * y + z * z), 2 * (x * y - w * z),     2 * (x * z + w * y),
          2 * (x * y + w * z),     1 - 2 * (x * x + z * z), 2 * (y * z - w * x),
          2 * (x * z - w * y),     2 * (y * z + w * x),     1 - 2 * (x * x + y * y)};
      double c[3];
      for (int r = 0; r < 3; ++r) {
        c[r] = R[3 * r] * p.xyz[0] + R[3 * r + 1] * p.xyz[1] + R[3 * r + 2] * p.xyz[2] + im.tvec[r];
      }
      const double u = cam[0] * c[0] / c[2] + cam[2], v = cam[1] * c[1] / c[2] + cam[3];
      EXPECT_NEAR(u, im.points2d[idx].x, 1e-2);
      int H = 0, W = 0;
      const std::string stem = im.name.substr(0, im.name.size() - 4);
      const auto depth = readNpy(dir.file("s/depth/" + stem + ".npy"), &H, &W);
      const int pu = static_cast<int>(u), pv = static_cast<int>(v);
      ASSERT_TRUE(pu >= 0 && pv >= 0 && pu < W && pv < H);
      EXPECT_NEAR(depth[pv * W + pu], c[2], 0.01 * c[2]) << "point " << k << " in " << im.name;
      label_agree += scene.views[image_id - 1].labels.at(pu, pv) == scene.points[k].cls;
      ++checked;
    }
  }
  // Points near a class boundary may land on the neighbouring pixel's class in another view.
  EXPECT_GT(label_agree, 0.93 * checked) << label_agree << " of " << checked;
}

// Structure from motion triangulates whatever the photos show: the orbit's photos see terrain
// beyond the labelled world, and the sparse points hold it (unlabelled, 255) as well as the
// world's own surfaces; no point lies in the sky (every one is on a surface its views see).
TEST(AerialBenchmark, SparsePointsIncludeTheTerrainBeyondTheWorld) {
  synth::SynthOptions o = small(synth::SceneKind::kCity, 0);
  o.max_points = 2000;
  const auto scene = synth::generate(o);
  const float extent = synth::World::extentOf(1);
  int beyond = 0, beyond_unlabelled = 0;
  for (const auto& p : scene.points) {
    const bool outside = std::fabs(p.xyz[0]) > extent || std::fabs(p.xyz[1]) > extent;
    beyond += outside;
    beyond_unlabelled += outside && p.cls == io::kIgnoreLabel;
    EXPECT_LT(std::fabs(p.xyz[2]), 100.f) << "a point far above or below the ground";
  }
  EXPECT_GT(beyond, 0.02 * scene.points.size()) << beyond << " of " << scene.points.size();
  EXPECT_EQ(beyond_unlabelled, beyond);
  EXPECT_LT(beyond, 0.8 * scene.points.size());
}

TEST(AerialBenchmark, WrittenScenesLoadThroughTheSceneImport) {
  const auto scene = synth::generate(small(synth::SceneKind::kPort, 5));
  test::TempDir dir;
  synth::writeScene(scene, dir.file("s"));
  const io::Scene imported = io::importScene(dir.file("s"));
  ASSERT_EQ(imported.views.size(), 10u);
  ASSERT_EQ(imported.classes.size(), 8u);
  EXPECT_EQ(imported.classes[0].name, "water");
  EXPECT_TRUE(imported.views[0].labelled && imported.views[7].labelled);
  EXPECT_TRUE(imported.views[3].test && !imported.views[3].train);
  EXPECT_FALSE(imported.views[1].labelled);
  EXPECT_EQ(imported.views[4].labels.pixels, scene.views[4].labels.pixels);  // all views labelled
  EXPECT_EQ(imported.points.size(), scene.points.size());
  const auto stats = synth::computeStats(scene);
  double sum = 0;
  for (double s : stats.class_share) sum += s;
  EXPECT_NEAR(sum, 1.0, 1e-9);
  EXPECT_GT(stats.effective_share, 0.5);
  // The in-memory conversion equals the import of the written directory.
  const io::Scene direct = synth::toScene(scene);
  ASSERT_EQ(direct.views.size(), imported.views.size());
  for (std::size_t i = 0; i < direct.views.size(); ++i) {
    EXPECT_EQ(direct.views[i].rgb.pixels, imported.views[i].rgb.pixels);
    EXPECT_EQ(direct.views[i].labelled, imported.views[i].labelled);
    EXPECT_EQ(direct.views[i].test, imported.views[i].test);
    EXPECT_DOUBLE_EQ(direct.views[i].camera.fx, imported.views[i].camera.fx);
  }
  EXPECT_EQ(direct.points.size(), imported.points.size());
}

TEST(AerialBenchmark, BinaryColmapModelHoldsWhatTheTextModelHolds) {
  const auto scene = synth::generate(small(synth::SceneKind::kCity, 3));
  test::TempDir dir;
  synth::writeScene(scene, dir.file("text"));
  synth::writeScene(scene, dir.file("bin"), synth::ColmapFormat::kBinary);
  EXPECT_TRUE(fs::exists(dir.file("bin/sparse/0/points3D.bin")));
  EXPECT_FALSE(fs::exists(dir.file("bin/sparse/0/points3D.txt")));
  EXPECT_FALSE(fs::exists(dir.file("text/sparse/0/points3D.bin")));
  const io::ColmapModel t = io::readColmapModel(dir.file("text/sparse/0"));
  const io::ColmapModel b = io::readColmapModel(dir.file("bin/sparse/0"));
  ASSERT_EQ(b.cameras.size(), t.cameras.size());
  EXPECT_EQ(b.cameras[0].params, t.cameras[0].params);
  ASSERT_EQ(b.images.size(), scene.views.size());
  ASSERT_EQ(b.images.size(), t.images.size());
  for (std::size_t i = 0; i < b.images.size(); ++i) {
    EXPECT_EQ(b.images[i].name, t.images[i].name);
    for (int k = 0; k < 3; ++k) EXPECT_NEAR(b.images[i].tvec[k], t.images[i].tvec[k], 1e-9);
    EXPECT_EQ(b.images[i].points2d.size(), t.images[i].points2d.size());
  }
  ASSERT_EQ(b.points.size(), scene.points.size());
  for (std::size_t k = 0; k < b.points.size(); k += 37) {
    for (int a = 0; a < 3; ++a) EXPECT_NEAR(b.points[k].xyz[a], scene.points[k].xyz[a], 1e-5);
    EXPECT_EQ(b.points[k].track.size(), t.points[k].track.size());
  }
  // Both load through the scene import as the same scene.
  EXPECT_EQ(io::importScene(dir.file("bin")).points.size(),
            io::importScene(dir.file("text")).points.size());
}

TEST(AerialBenchmark, BadOptionsAreClearErrors) {
  EXPECT_THROW(synth::parseSceneKind("desert"), Error);
  auto o = small(synth::SceneKind::kCity, 0);
  o.labelled = {12};
  try {
    synth::generate(o);
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "--labelled");
  }
}

TEST(AerialBenchmark, CityXlIsFourTilesWithTheirOwnOrbitsAndSplits) {
  const synth::World one(synth::SceneKind::kCity, 3), xl(synth::SceneKind::kCity, 3, 2);
  EXPECT_EQ(xl.extent(), 2 * one.extent());
  EXPECT_GT(xl.objects().size(), 3 * one.objects().size());
  EXPECT_THROW(synth::World(synth::SceneKind::kPort, 3, 2), Error);
  EXPECT_THROW(synth::World(synth::SceneKind::kCity, 3, 0), Error);

  const synth::SynthOptions full = synth::SynthOptions::cityXl(5);
  EXPECT_EQ(full.views, 280);
  ASSERT_EQ(full.labelled.size(), 12u);
  ASSERT_EQ(full.test.size(), 28u);
  int labelled_per_tile[4] = {0, 0, 0, 0};
  for (int v : full.labelled) {
    ++labelled_per_tile[v % 4];
    EXPECT_EQ(std::count(full.test.begin(), full.test.end(), v), 0) << v;
  }
  for (int n : labelled_per_tile) EXPECT_EQ(n, 3);
  // city-xxl: 4 x 4 tiles (16x the area), 1,120 views, every tile split as the ordinary scene.
  const synth::SynthOptions xxl = synth::SynthOptions::tiledCity(5, 4);
  EXPECT_EQ(xxl.views, 1120);
  EXPECT_EQ(xxl.max_points, 320000);
  ASSERT_EQ(xxl.labelled.size(), 48u);
  ASSERT_EQ(xxl.test.size(), 112u);
  std::vector<int> test_per_tile(16, 0);
  for (int v : xxl.test) ++test_per_tile[v % 16];
  for (int n : test_per_tile) EXPECT_EQ(n, 7);
  EXPECT_EQ(synth::World(synth::SceneKind::kCity, 3, 4).extent(), 4 * one.extent());

  // View i looks at the centre of tile i % 4 (+-4 m of jitter): its optical axis meets the ground
  // there.
  synth::SynthOptions o = full;
  o.views = 8;
  o.width = 48;
  o.height = 27;
  o.max_points = 200;
  o.labelled = {0, 1};
  o.test = {6, 7};
  const synth::SynthScene scene = synth::generate(o);
  for (int i = 0; i < o.views; ++i) {
    const auto& q = scene.views[i].camera.qvec;
    const auto& t = scene.views[i].camera.tvec;
    const double w = q[0], x = q[1], y = q[2], z = q[3];
    // Rows of the world-to-camera rotation; the third is the optical axis.
    const double R[3][3] = {{1 - 2 * (y * y + z * z), 2 * (x * y - w * z), 2 * (x * z + w * y)},
                            {2 * (x * y + w * z), 1 - 2 * (x * x + z * z), 2 * (y * z - w * x)},
                            {2 * (x * z - w * y), 2 * (y * z + w * x), 1 - 2 * (x * x + y * y)}};
    double c[3];
    for (int k = 0; k < 3; ++k) c[k] = -(R[0][k] * t[0] + R[1][k] * t[1] + R[2][k] * t[2]);
    const double along = -c[2] / R[2][2];
    const double gx = c[0] + along * R[2][0], gy = c[1] + along * R[2][1];
    const double tx = (i % 2 == 0 ? -100 : 100), ty = ((i % 4) / 2 == 0 ? -100 : 100);
    EXPECT_NEAR(gx, tx, 5.0) << i;
    EXPECT_NEAR(gy, ty, 5.0) << i;
  }
}

// The grid capture flies a drone-mapping mission: nadir photos (within the gimbal's ~1 degree)
// at the stated altitude on parallel lines, 75 % forward overlap over flat ground, ~60 % side.
TEST(AerialBenchmark, TheGridCaptureFliesNadirLinesWithTheStatedOverlap) {
  synth::SynthOptions o = synth::SynthOptions::demo(synth::SceneKind::kCity, 3);
  o.capture = synth::Capture::kGrid;
  o.views = 36;
  o.width = 160;
  o.height = 90;
  o.max_points = 500;
  const synth::GridLayout g = synth::gridLayout(o);
  EXPECT_EQ(g.lines, 4);
  EXPECT_EQ(g.per_line, 9);
  EXPECT_NEAR(g.forward_overlap, 0.75, 1e-9);
  EXPECT_GT(g.side_overlap, 0.55);
  EXPECT_LT(g.side_overlap, 0.70);
  const synth::SynthScene scene = synth::generate(o);
  ASSERT_EQ(scene.views.size(), 36u);
  for (int i = 0; i < 36; ++i) {
    const auto& c = scene.views[i].camera;
    const Eigen::Quaterniond q(c.qvec[0], c.qvec[1], c.qvec[2], c.qvec[3]);
    const Eigen::Matrix3d R = q.normalized().toRotationMatrix();
    const Eigen::Vector3d centre =
        -R.transpose() * Eigen::Vector3d(c.tvec[0], c.tvec[1], c.tvec[2]);
    const Eigen::Vector3d viewing = R.transpose() * Eigen::Vector3d::UnitZ();
    EXPECT_LT(std::acos(-viewing.z()) * 180 / M_PI, 1.0) << i;  // nadir
    EXPECT_NEAR(centre.z(), g.altitude, 1.0) << i;
    EXPECT_LE(std::abs(centre.x()), 0.9 * 100 + 0.5) << i;
    EXPECT_LE(std::abs(centre.y()), 0.9 * 100 + 0.5) << i;
    // Consecutive photos of a line: one spacing apart, the line's x shared.
    if (i % g.per_line != 0) {
      const auto& p = scene.views[i - 1].camera;
      const Eigen::Matrix3d Rp = Eigen::Quaterniond(p.qvec[0], p.qvec[1], p.qvec[2], p.qvec[3])
                                     .normalized()
                                     .toRotationMatrix();
      const Eigen::Vector3d prev =
          -Rp.transpose() * Eigen::Vector3d(p.tvec[0], p.tvec[1], p.tvec[2]);
      EXPECT_NEAR(std::abs(centre.y() - prev.y()), g.along_spacing, 1.0) << i;
      EXPECT_NEAR(centre.x(), prev.x(), 1.0) << i;
    }
  }
  EXPECT_EQ(synth::captureFromName(synth::captureName(synth::Capture::kGrid)),
            synth::Capture::kGrid);
  EXPECT_THROW(synth::captureFromName("spiral"), Error);
}

// --labelled auto: the views a user is advised to annotate. On the port's drone mission the
// default indices (0, 7, 28: nadir photos of the first lines) show no ship and no crane; the
// chosen views are training views that together show every class.
TEST(AerialBenchmark, AutoLabelledViewsAreTrainingViewsShowingEveryClass) {
  synth::SynthOptions o = synth::SynthOptions::demo(synth::SceneKind::kPort, 2);
  o.capture = synth::Capture::kGridOblique;
  o.views = 70;
  o.width = 96;
  o.height = 54;
  o.max_points = 3000;
  const auto classesShown = [](const synth::SynthScene& scene) {
    std::set<int> shown;
    for (const std::string& name : scene.split.labelled) {
      for (const synth::SynthView& v : scene.views) {
        if (v.name != name) continue;
        for (std::uint8_t l : v.labels.pixels)
          if (l != 255) shown.insert(l);
      }
    }
    return shown;
  };
  const synth::SynthScene fixed = synth::generate(o);
  o.labelled_auto = true;
  const synth::SynthScene chosen = synth::generate(o);
  ASSERT_EQ(chosen.split.labelled.size(), 3u);
  EXPECT_NE(chosen.split.labelled, fixed.split.labelled);
  for (const std::string& name : chosen.split.labelled) {
    EXPECT_NE(std::find(chosen.split.train.begin(), chosen.split.train.end(), name),
              chosen.split.train.end())
        << name;
  }
  EXPECT_EQ(classesShown(chosen).size(), chosen.classes.size());
  EXPECT_LT(classesShown(fixed).size(), chosen.classes.size());
  // Only the split differs.
  ASSERT_EQ(chosen.views.size(), fixed.views.size());
  EXPECT_EQ(chosen.views[5].rgb.pixels, fixed.views[5].rgb.pixels);
  EXPECT_EQ(chosen.split.test, fixed.split.test);
}

// Grid-oblique: the first half nadir on the grid, the second half on four passes at the same
// altitude pitched 45 degrees towards north, east, south and west in turn.
TEST(AerialBenchmark, TheGridObliqueCaptureAddsFourPassesPitched45Degrees) {
  synth::SynthOptions o = synth::SynthOptions::demo(synth::SceneKind::kCity, 3);
  o.capture = synth::Capture::kGridOblique;
  o.views = 40;
  o.width = 160;
  o.height = 90;
  o.max_points = 500;
  EXPECT_EQ(synth::nadirViews(o), 20);
  const synth::GridLayout g = synth::gridLayout(o);
  EXPECT_NEAR(g.forward_overlap, 0.75, 1e-9);
  const synth::SynthScene scene = synth::generate(o);
  ASSERT_EQ(scene.views.size(), 40u);
  int towards[4] = {0, 0, 0, 0};  // north, east, south, west
  for (int i = 0; i < 40; ++i) {
    const auto& c = scene.views[i].camera;
    const Eigen::Matrix3d R =
        Eigen::Quaterniond(c.qvec[0], c.qvec[1], c.qvec[2], c.qvec[3]).normalized().toRotationMatrix();
    const Eigen::Vector3d centre = -R.transpose() * Eigen::Vector3d(c.tvec[0], c.tvec[1], c.tvec[2]);
    const Eigen::Vector3d viewing = R.transpose() * Eigen::Vector3d::UnitZ();
    const double off_nadir = std::acos(-viewing.z()) * 180 / M_PI;
    EXPECT_NEAR(centre.z(), g.altitude, 1.0) << i;
    if (i < 20) {
      EXPECT_LT(off_nadir, 1.0) << i;
      continue;
    }
    EXPECT_NEAR(off_nadir, synth::kObliquePitchDeg, 0.5) << i;
    const int k = (i - 20) % 4;
    const Eigen::Vector2d expected[4] = {{0, 1}, {1, 0}, {0, -1}, {-1, 0}};
    EXPECT_GT(viewing.head<2>().normalized().dot(expected[k]), 0.999) << i;
    // It looks at the labelled area: the ray through the image centre meets the ground inside.
    const Eigen::Vector3d ground = centre - centre.z() / viewing.z() * viewing;
    EXPECT_LE(std::abs(ground.x()), 100.0) << i;
    EXPECT_LE(std::abs(ground.y()), 100.0) << i;
    ++towards[k];
  }
  for (int k = 0; k < 4; ++k) EXPECT_EQ(towards[k], 5) << k;
  EXPECT_EQ(synth::captureFromName("grid-oblique"), synth::Capture::kGridOblique);
  EXPECT_EQ(synth::captureName(synth::Capture::kGridOblique), "grid-oblique");
}

}  // namespace
}  // namespace sadsplat
