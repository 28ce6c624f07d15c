// The GIS outputs through the CLI, on a small synth scene trained for a few iterations: `render`
// (class ids per view, sizes, orbit), `ortho` (GeoTIFFs read back by GDAL's gdalinfo, classes.csv),
// `eval --ortho`, LAS from `convert`, and the one-line errors of bad options.
#include <gtest/gtest.h>

#include <nlohmann/json.hpp>

#include <algorithm>
#include <cmath>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/geodesy.h"
#include "sadsplat/geo/ground_model.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/raster_files.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/las.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/scene_import.h"
#include "sadsplat/synth/world.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kCli;

class MapProducts : public ::testing::Test {
 protected:
  static void SetUpTestSuite() {
    if (!io::haveSceneImport() || !geo::haveGdal()) return;
    dir_ = new test::TempDir();
    std::string out;
    const std::string scene = dir_->file("scene");
    ASSERT_EQ(test::runCommand(kCli + " synth --kind city --views 16 --width 160 --height 90 " +
                                   "--points 2000 --labelled 0,7 --out " + scene,
                               &out),
              0)
        << out;
    // The same scene, placed on the Earth (its frame read as east-north-up metres).
    test::copyTree(scene, dir_->file("geo_scene"));
    io::Georeference g;
    g.origin = {46.843, -91.994, 200.0};
    g.epsg_utm = geo::utmEpsg(g.origin);
    test::writeFile(dir_->file("geo_scene/georeference.json"), io::georeferenceToJson(g));
  }
  static void TearDownTestSuite() {
    delete dir_;
    dir_ = nullptr;
  }
  void SetUp() override {
    if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
    if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
    if (test::runCommand("gdalinfo --version") != 0) GTEST_SKIP() << "no gdalinfo (gdal-bin)";
  }
  // ctest runs the suite as one process (tests/CMakeLists.txt): a run is trained when a test
  // first asks for it, then shared.
  static std::string trained(const std::string& scene) {
    const std::string run = dir_->file(scene + "_run");
    if (!io::pathExists(run + "/checkpoint.bin")) {
      std::string out;
      EXPECT_EQ(test::runCommand(kCli + " train " + dir_->file(scene) +
                                     " --scale 1 --iterations 40 --out " + run,
                                 &out),
                0)
          << out;
    }
    return run;
  }
  static std::string run() { return trained("scene"); }
  static std::string geoRun() { return trained("geo_scene"); }
  // `ortho` of the shared run at 0.5 m with `args`, into a folder `name`; its path.
  static std::string ortho(const std::string& args, const std::string& name) {
    std::string out;
    const std::string dir = dir_->file(name);
    EXPECT_EQ(
        test::runCommand(kCli + " ortho " + run() + " --gsd 0.5 " + args + " --out " + dir, &out),
        0)
        << out;
    return dir;
  }
  static test::TempDir* dir_;
};
test::TempDir* MapProducts::dir_ = nullptr;

std::vector<ClassInfo> classesOf(const std::string& run) {
  return io::readClassesJson(run + "/classes.json");
}

TEST_F(MapProducts, RenderWritesAClassIdImageForEveryViewWithItsPaletteAndConfidence) {
  std::string out;
  const std::string dir = dir_->file("render_all");
  ASSERT_EQ(test::runCommand(kCli + " render " + run() + " --out " + dir, &out), 0) << out;
  EXPECT_NE(out.find("wrote 16 views"), std::string::npos) << out;
  const auto classes = classesOf(run());
  int files = 0;
  for (int i = 0; i < 16; ++i) {
    char name[32];
    std::snprintf(name, sizeof(name), "view_%03d", i);
    const geo::Raster ids = geo::readByteRaster(dir + "/class/" + name + ".png");
    const geo::Raster conf = geo::readByteRaster(dir + "/confidence/" + name + ".png");
    ASSERT_EQ(ids.width, 160);  // the photos' own size
    ASSERT_EQ(ids.height, 90);
    std::set<int> seen;
    for (std::size_t p = 0; p < ids.bytes.size(); ++p) {
      const int id = ids.bytes[p];
      ASSERT_TRUE(id < static_cast<int>(classes.size()) || id == 255) << name << " " << id;
      if (id == 255) {
        ASSERT_EQ(conf.bytes[p], 0);
      }
      seen.insert(id);
    }
    EXPECT_GE(seen.size(), 2u) << name;  // a city view shows several classes
    ++files;
  }
  EXPECT_EQ(files, 16);
  // The colour image is the class image through the palette (checked on one view, via GDAL's
  // reader of the RGB PNG: band 1 = red).
  const geo::Raster ids = geo::readByteRaster(dir + "/class/view_003.png");
  const geo::Raster red = geo::readByteRaster(dir + "/colour/view_003.png");
  for (std::size_t p = 0; p < ids.bytes.size(); p += 97) {
    if (ids.bytes[p] == 255) continue;
    EXPECT_EQ(red.bytes[p], classes[ids.bytes[p]].color[0]);
  }
  std::string info;
  ASSERT_EQ(test::runCommand("gdalinfo " + dir + "/depth/view_003.tif", &info), 0);
  EXPECT_NE(info.find("Type=Float32"), std::string::npos) << info;
}

TEST_F(MapProducts, RenderSizesNamesAndOrbit) {
  std::string out;
  const std::string dir = dir_->file("render_some");
  ASSERT_EQ(test::runCommand(kCli + " render " + run() + " --out " + dir +
                                 " --views view_014,view_002.png --size 64x36 --outputs class,rgb",
                             &out),
            0)
      << out;
  const auto size = geo::imageFileSize(dir + "/rgb/view_014.png");
  ASSERT_TRUE(size.has_value());
  EXPECT_EQ((*size)[0], 64);
  EXPECT_EQ((*size)[1], 36);
  EXPECT_TRUE(io::pathExists(dir + "/class/view_002.png"));
  EXPECT_FALSE(io::pathExists(dir + "/depth"));
  ASSERT_EQ(test::runCommand(kCli + " render " + run() + " --out " + dir +
                                 "_orbit --path orbit:3 " + "--scale 0.5",
                             &out),
            0)
      << out;
  for (const char* n : {"orbit_000", "orbit_001", "orbit_002"}) {
    const auto s = geo::imageFileSize(dir + "_orbit/class/" + n + ".png");
    ASSERT_TRUE(s.has_value()) << n;
    EXPECT_EQ((*s)[0], 80);
  }
}

std::string gdalinfo(const std::string& path) {
  std::string info;
  EXPECT_EQ(test::runCommand("gdalinfo " + path, &info), 0) << info;
  return info;
}

TEST_F(MapProducts, OrthoWritesGeoTiffsGdalReadsWithTheGridAndLocalCrs) {
  std::string out;
  const std::string dir = dir_->file("ortho");
  ASSERT_EQ(test::runCommand(kCli + " ortho " + run() + " --gsd 1.5 --out " + dir, &out), 0) << out;
  std::ifstream json(dir + "/ortho.json");
  std::stringstream text;
  text << json.rdbuf();
  const std::string j = text.str();
  for (const char* f : {"orthophoto.tif", "classes.tif", "dsm.tif", "confidence.tif"}) {
    const std::string info = gdalinfo(dir + "/" + f);
    EXPECT_NE(info.find("Pixel Size = (1.500000000000000,-1.500000000000000)"), std::string::npos)
        << f << "\n"
        << info;
    EXPECT_NE(info.find("sadsplat local metres"), std::string::npos) << f;
  }
  const std::string classes = gdalinfo(dir + "/classes.tif");
  EXPECT_NE(classes.find("ColorInterp=Palette"), std::string::npos) << classes;
  EXPECT_NE(classes.find("NoData Value=255"), std::string::npos) << classes;
  EXPECT_NE(gdalinfo(dir + "/dsm.tif").find("NoData Value=-9999"), std::string::npos);
  EXPECT_NE(gdalinfo(dir + "/orthophoto.tif").find("ColorInterp=Alpha"), std::string::npos);
  // classes.csv: areas are pixels x gsd^2, shares sum to 1, and the pixel counts are those of
  // classes.tif.
  const geo::Raster ids = geo::readByteRaster(dir + "/classes.tif");
  // ortho.json's grid is the rasters' (its height once lost to the surface mode's key).
  const nlohmann::json grid = nlohmann::json::parse(j);
  EXPECT_EQ(grid["width"], ids.width);
  EXPECT_EQ(grid["height"], ids.height);
  EXPECT_EQ(grid["height_from"], "first");
  std::map<int, long> counted;
  for (std::uint8_t v : ids.bytes) ++counted[v];
  std::ifstream csv(dir + "/classes.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line, "class_id,name,pixels,area_m2,share");
  double share_sum = 0;
  while (std::getline(csv, line)) {
    std::stringstream row(line);
    std::string id, name, pixels, area, share;
    std::getline(row, id, ',');
    std::getline(row, name, ',');
    std::getline(row, pixels, ',');
    std::getline(row, area, ',');
    std::getline(row, share, ',');
    EXPECT_EQ(std::stol(pixels), counted[std::stoi(id)]) << line;
    EXPECT_NEAR(std::stod(area), std::stol(pixels) * 2.25, 0.01) << line;
    if (!share.empty()) share_sum += std::stod(share);
  }
  EXPECT_NEAR(share_sum, 1.0, 1e-4);
}

// Nodata where too few photos see the surface: a count no cell reaches leaves the map empty,
// and every cell it took is counted; 0 (the default) keeps every covered cell, 2 a subset.
TEST_F(MapProducts, OrthoMinViewsMakesCellsFewPhotosSeeNodata) {
  const auto covered = [&](const std::string& args, double* few) {
    std::string out;
    const std::string dir = dir_->file("ortho_views");
    EXPECT_EQ(
        test::runCommand(kCli + " ortho " + run() + " --gsd 1.5 " + args + " --out " + dir, &out),
        0)
        << out;
    const nlohmann::json j = nlohmann::json::parse(test::readFile(dir + "/ortho.json"));
    *few = j["few_views_share"].get<double>();
    return j["covered_share"].get<double>();
  };
  double few_all = 0, few_default = 0, few_none = 0;
  const double all = covered("", &few_all);  // the default: 0, every covered cell
  const double by_default = covered("--min-views 2", &few_default);
  const double none = covered("--min-views 100000", &few_none);
  EXPECT_EQ(few_all, 0.0);
  EXPECT_GT(all, 0.1);
  EXPECT_LE(by_default, all);
  EXPECT_NEAR(by_default + few_default, all, 1e-9);
  EXPECT_EQ(none, 0.0);
  EXPECT_NEAR(few_none, all, 1e-9);
  // One-sided views: a spread no set of photos reaches (360 degrees: the unit vectors would have
  // to cancel exactly) leaves nothing; a small one with two views keeps a subset of those two views
  // keep.
  double few_spread = 0;
  EXPECT_EQ(covered("--min-spread 360", &few_spread), 0.0);
  EXPECT_LE(covered("--min-views 2 --min-spread 30", &few_spread), by_default);
  // The blend through the Gaussians is still there on request.
  double few_blend = 0;
  EXPECT_GT(covered("--height blend --class-from first --min-views 0", &few_blend), 0.1);
}

// --on-surface M makes the maps of the Gaussians at most M from the surface the photos render:
// the kept sets grow with M and a cell's accumulated alpha only grows with more Gaussians, so the
// covered share grows with M up to the map of every Gaussian (M = 0, the default); ortho.json
// says which M made it.
TEST_F(MapProducts, OrthoOnSurfaceMapsOnlyTheGaussiansNearTheRenderedSurface) {
  const auto covered = [&](const std::string& m) {
    std::string out;
    const std::string dir = dir_->file("ortho_surface");
    EXPECT_EQ(
        test::runCommand(
            kCli + " ortho " + run() + " --gsd 1.5 --on-surface " + m + " --out " + dir, &out),
        0)
        << out;
    const nlohmann::json j = nlohmann::json::parse(test::readFile(dir + "/ortho.json"));
    EXPECT_EQ(j["on_surface_m"].get<double>(), std::stod(m));
    return j["covered_share"].get<double>();
  };
  const double all = covered("0"), wide = covered("5"), narrow = covered("0.3"),
               none = covered("0.000001");
  EXPECT_GT(all, 0.1);
  EXPECT_LE(wide, all);
  EXPECT_LE(narrow, wide);
  EXPECT_LE(none, narrow);
  EXPECT_LT(none, all);
}

// --raised-check (on by default): ortho.json gives every class's median height above the ground and
// which classes are raised; the cells it changes were of a raised class and are now of a ground
// class (median below half the raised height), nothing else changes.
TEST_F(MapProducts, OrthoRaisedCheckChangesOnlyRaisedCellsToGroundClasses) {
  const std::string plain = ortho("--raised-check 0", "ortho_plain"),
                    checked = ortho("--raised-check 0.5 --ground-window 8", "ortho_raised");
  const nlohmann::json j = nlohmann::json::parse(test::readFile(checked + "/ortho.json"));
  const std::vector<ClassInfo> classes = classesOf(run());
  EXPECT_EQ(nlohmann::json::parse(
                test::readFile(ortho("", "ortho_default") + "/ortho.json"))["raised_check"]
                .get<double>(),
            0.33);
  ASSERT_EQ(j["raised_check"].get<double>(), 0.5);
  ASSERT_EQ(j["ground_window"].get<double>(), 8.0);
  std::set<std::string> raised, ground;
  for (const auto& c : classes) {
    ASSERT_TRUE(j["class_height_above_ground"].contains(c.name)) << c.name;
    const nlohmann::json& h = j["class_height_above_ground"][c.name];
    if (h.is_null()) continue;
    if (h.get<double>() >= 2.5) raised.insert(c.name);
    if (h.get<double>() < 1.25) ground.insert(c.name);
  }
  std::set<std::string> listed;
  for (const auto& r : j["raised_classes"]) listed.insert(r.get<std::string>());
  EXPECT_EQ(listed, raised);
  const geo::Raster a = geo::readByteRaster(plain + "/classes.tif");
  const geo::Raster b = geo::readByteRaster(checked + "/classes.tif");
  ASSERT_EQ(a.bytes.size(), b.bytes.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.bytes.size(); ++i) {
    if (a.bytes[i] == b.bytes[i]) continue;
    ++changed;
    ASSERT_LT(a.bytes[i], classes.size());
    ASSERT_LT(b.bytes[i], classes.size());
    EXPECT_TRUE(raised.count(classes[a.bytes[i]].name)) << classes[a.bytes[i]].name;
    EXPECT_TRUE(ground.count(classes[b.bytes[i]].name)) << classes[b.bytes[i]].name;
  }
  const double share = j["raised_lowered_share"].get<double>();
  EXPECT_NEAR(share, double(changed) / a.bytes.size(), 1e-12);
  if (j["raised_check_applied"].get<bool>()) {
    EXPECT_GE(j["near_ground_share"].get<double>(), geo::kMinNearGround);
  } else {
    EXPECT_EQ(changed, 0u);
  }
}

// A float GeoTIFF's band 1 as GDAL's own tool reads it (gdal_translate to XYZ text), row by row.
std::vector<double> gdalFloats(const std::string& tif, const std::string& xyz) {
  std::string out;
  EXPECT_EQ(test::runCommand("gdal_translate -q -of XYZ " + tif + " " + xyz, &out), 0) << out;
  std::ifstream f(xyz);
  std::vector<double> v;
  double x, y, z;
  while (f >> x >> y >> z) v.push_back(z);
  return v;
}

// The ground classes' ids as ortho.json `j` reports them: a median height above the ground below
// half the raised height (1.25 m).
std::set<std::size_t> groundClassIds(const nlohmann::json& j,
                                     const std::vector<ClassInfo>& classes) {
  std::set<std::size_t> ground;
  for (std::size_t c = 0; c < classes.size(); ++c) {
    const nlohmann::json& h = j["class_height_above_ground"][classes[c].name];
    if (!h.is_null() && h.get<double>() < 1.25) ground.insert(c);
  }
  return ground;
}

// `ortho --pit-depth`: the DSM cells it changes are of a ground class and raised by more than the
// depth; nothing else changes, and ortho.json counts them.
TEST_F(MapProducts, OrthoPitDepthRaisesOnlyGroundClassCellsInPits) {
  const std::string plain = ortho("--pit-depth 0", "ortho_pits_off"),
                    filled = ortho("--pit-depth 0.5 --ground-window 8", "ortho_pits");
  const nlohmann::json j = nlohmann::json::parse(test::readFile(filled + "/ortho.json"));
  EXPECT_EQ(nlohmann::json::parse(test::readFile(plain + "/ortho.json"))["pit_depth"], 0.0);
  ASSERT_EQ(j["pit_depth"].get<double>(), 0.5);
  const std::set<std::size_t> ground = groundClassIds(j, classesOf(run()));
  const std::vector<double> a = gdalFloats(plain + "/dsm.tif", dir_->file("a.xyz"));
  const std::vector<double> b = gdalFloats(filled + "/dsm.tif", dir_->file("b.xyz"));
  const geo::Raster cls = geo::readByteRaster(filled + "/classes.tif");
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), cls.bytes.size());
  std::size_t changed = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a[i] == b[i]) continue;
    ++changed;
    EXPECT_GT(b[i], a[i] + 0.5) << i;
    EXPECT_TRUE(ground.count(cls.bytes[i])) << int(cls.bytes[i]);
  }
  EXPECT_NEAR(j["pit_filled_share"].get<double>(), double(changed) / a.size(), 1e-12);
  if (!j["pit_depth_applied"].get<bool>()) {
    EXPECT_EQ(changed, 0u);
  }
  std::string out;
  EXPECT_EQ(test::runCommand(
                kCli + " ortho " + run() + " --pit-depth -1 --out " + dir_->file("bad_pits"), &out),
            1);
  EXPECT_NE(out.find("--pit-depth"), std::string::npos) << out;
}

// `ortho --spike-height`: the DSM cells it changes are of a ground class and lowered by more than
// the height; the class map does not change; ortho.json counts them. The clearance spares the
// cells near a raised class: never more cells changed with it.
TEST_F(MapProducts, OrthoSpikeHeightLowersOnlyGroundClassCellsStandingHigh) {
  const std::string plain = ortho("--ground-window 8", "ortho_spikes_off"),
                    lowered = ortho("--spike-height 0.5 --spike-clearance 0 --ground-window 8",
                                    "ortho_spikes"),
                    spared = ortho("--spike-height 0.5 --ground-window 8", "ortho_spikes_spared");
  const nlohmann::json j = nlohmann::json::parse(test::readFile(lowered + "/ortho.json"));
  const nlohmann::json off = nlohmann::json::parse(test::readFile(plain + "/ortho.json"));
  EXPECT_EQ(off["spike_height"], 0.0);
  EXPECT_FALSE(off.contains("spike_clearance"));
  ASSERT_EQ(j["spike_height"].get<double>(), 0.5);
  ASSERT_EQ(j["spike_clearance"].get<double>(), 0.0);
  const std::set<std::size_t> ground = groundClassIds(j, classesOf(run()));
  const std::vector<double> a = gdalFloats(plain + "/dsm.tif", dir_->file("sa.xyz"));
  const std::vector<double> b = gdalFloats(lowered + "/dsm.tif", dir_->file("sb.xyz"));
  const std::vector<double> c = gdalFloats(spared + "/dsm.tif", dir_->file("sc.xyz"));
  const geo::Raster cls = geo::readByteRaster(lowered + "/classes.tif");
  EXPECT_EQ(cls.bytes, geo::readByteRaster(plain + "/classes.tif").bytes);
  ASSERT_EQ(a.size(), b.size());
  ASSERT_EQ(a.size(), c.size());
  ASSERT_EQ(a.size(), cls.bytes.size());
  std::size_t changed = 0, changed_spared = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (c[i] != a[i]) {
      ++changed_spared;
      EXPECT_EQ(c[i], b[i]) << i;  // a spared run lowers a cell as the unspared one does
    }
    if (a[i] == b[i]) continue;
    ++changed;
    EXPECT_LT(b[i], a[i] - 0.5) << i;
    EXPECT_TRUE(ground.count(cls.bytes[i])) << int(cls.bytes[i]);
  }
  EXPECT_NEAR(j["spike_lowered_share"].get<double>(), double(changed) / a.size(), 1e-12);
  EXPECT_LE(changed_spared, changed);
  if (!j["spike_height_applied"].get<bool>()) {
    EXPECT_EQ(changed, 0u);
  }
  for (const char* bad :
       {"--spike-height -1", "--spike-clearance -1", "--trim none --trim-whole-under -1"}) {
    std::string out;
    EXPECT_EQ(
        test::runCommand(
            kCli + " ortho " + run() + " " + bad + " --out " + dir_->file("bad_spikes"), &out),
        1)
        << bad;
    const std::string flag = std::string(bad).substr(std::string(bad).rfind("--"));
    EXPECT_NE(out.find(flag.substr(0, flag.find(' '))), std::string::npos) << out;
  }
}

// `ortho --class-from views`: the class map from the classes the training views give the
// Gaussians (OrthoClassSource::kViews); its confidence is the class's share of the blending weight,
// at least 1 / classes wherever a class is given; the covered cells and the DSM are the blend's.
TEST_F(MapProducts, OrthoClassFromViewsGivesEveryCoveredCellAClassAndAWeightShare) {
  // Without the checks that move classes or heights after the render (each its own test).
  const std::string plain = "--trim none --raised-check 0 --pit-depth 0";
  const std::string blend = ortho(plain + " --class-from blend", "ortho_class_blend"),
                    views = ortho(plain, "ortho_class_views");  // the default
  const nlohmann::json j = nlohmann::json::parse(test::readFile(views + "/ortho.json"));
  EXPECT_EQ(j["class_from"], "views");
  const std::size_t k = classesOf(run()).size();
  const geo::Raster cls = geo::readByteRaster(views + "/classes.tif");
  const geo::Raster cls_blend = geo::readByteRaster(blend + "/classes.tif");
  const std::vector<double> conf = gdalFloats(views + "/confidence.tif", dir_->file("cv.xyz"));
  EXPECT_EQ(gdalFloats(views + "/dsm.tif", dir_->file("dv.xyz")),
            gdalFloats(blend + "/dsm.tif", dir_->file("db.xyz")));
  ASSERT_EQ(cls.bytes.size(), conf.size());
  ASSERT_EQ(cls.bytes.size(), cls_blend.bytes.size());
  std::size_t classed = 0, differ = 0;
  for (std::size_t i = 0; i < conf.size(); ++i) {
    EXPECT_EQ(cls.bytes[i] == 255, cls_blend.bytes[i] == 255) << i;  // the same covered cells
    if (cls.bytes[i] == 255) continue;
    ++classed;
    differ += cls.bytes[i] != cls_blend.bytes[i];
    EXPECT_LT(cls.bytes[i], k);
    EXPECT_GE(conf[i], 1.0 / k - 1e-5) << i;
    EXPECT_LE(conf[i], 1.0 + 1e-5) << i;
  }
  EXPECT_GT(classed, conf.size() / 4);
  EXPECT_GT(differ, 0u);  // another rule, not the blend's map under another name
}

TEST_F(MapProducts, OrthoBoundsSetTheGrid) {
  std::string out;
  const std::string dir = dir_->file("ortho_bounds");
  ASSERT_EQ(test::runCommand(
                kCli + " ortho " + run() + " --gsd 0.5 --bounds -20,-10,30,15 --out " + dir, &out),
            0)
      << out;
  const std::string info = gdalinfo(dir + "/classes.tif");
  EXPECT_NE(info.find("Size is 100, 50"), std::string::npos) << info;
  EXPECT_NE(info.find("Origin = (-20.000000000000000,15.000000000000000)"), std::string::npos)
      << info;
}

// Checks OUT/objects/ of `ortho --vectors WANTED --object-clouds --object-min-opacity 0.05` in
// `dir` (see OrthoObjectClouds... below); `checked`: the object clouds whose polygon OGR read.
void checkObjectClouds(const std::string& dir, const std::vector<ClassInfo>& classes,
                       const std::set<std::string>& wanted, double gsd, int* checked_out) {
  const nlohmann::json j = nlohmann::json::parse(test::readFile(dir + "/ortho.json"));
  ASSERT_TRUE(j.contains("object_clouds")) << j.dump();
  // The polygons' bounding boxes by object id, as OGR reads them.
  std::string boxes;
  ASSERT_EQ(test::runCommand("ogrinfo -q -dialect SQLite -sql \"SELECT object_id, class_id, "
                             "ST_MinX(geom) AS x0, ST_MaxX(geom) AS x1, ST_MinY(geom) AS y0, "
                             "ST_MaxY(geom) AS y1 FROM classes\" " +
                                 dir + "/vectors.gpkg",
                             &boxes),
            0)
      << boxes;
  std::map<int, std::array<double, 5>> polygons;  // class, x0, x1, y0, y1
  {
    std::istringstream in(boxes);
    std::string line;
    int id = -1;
    std::array<double, 5> box{};
    int filled = 0;
    while (std::getline(in, line)) {
      const std::size_t eq = line.find(" = ");
      if (eq == std::string::npos) continue;
      const double v = std::stod(line.substr(eq + 3));
      const std::string key = line.substr(0, line.find(" ("));
      const std::size_t at = key.find_first_not_of(' ');
      const std::string name = key.substr(at);
      if (name == "object_id") id = static_cast<int>(v), filled = 0;
      const std::vector<std::string> keys = {"class_id", "x0", "x1", "y0", "y1"};
      const auto k = std::find(keys.begin(), keys.end(), name);
      if (k != keys.end()) box[k - keys.begin()] = v, ++filled;
      if (filled == 5) polygons[id] = box, filled = 0;
    }
  }
  ASSERT_GT(polygons.size(), 0u) << boxes;
  std::ifstream csv(dir + "/objects/objects.csv");
  std::string line;
  std::getline(csv, line);
  EXPECT_EQ(line,
            "object_id,class_id,class,gaussians,centroid_x,centroid_y,centroid_z,map_x,map_y,"
            "height_m,file,las_file");
  std::size_t files = 0, gaussians = 0;
  std::set<int> ids;
  std::string las_wkt;
  int checked = 0;
  while (std::getline(csv, line)) {
    std::vector<std::string> f;
    std::stringstream row(line);
    std::string cell;
    while (std::getline(row, cell, ',')) f.push_back(cell);
    if (!line.empty() && line.back() == ',') f.push_back("");
    ASSERT_EQ(f.size(), 12u) << line;
    const int id = std::stoi(f[0]), cls = std::stoi(f[1]);
    ids.insert(id);
    EXPECT_EQ(f[2], classes[cls].name) << line;
    EXPECT_EQ(wanted.count(f[2]), 1u) << line;
    const std::size_t n = std::stoul(f[3]);
    if (n == 0) {
      EXPECT_TRUE(f[10].empty()) << line;
      EXPECT_TRUE(f[11].empty()) << line;
      continue;
    }
    ASSERT_EQ(f[10], "object_" + f[0] + ".pcd") << line;
    ASSERT_EQ(f[11], "object_" + f[0] + ".las") << line;
    // The LAS holds the same points on the map: their mean is the CSV's map position, in the
    // map's CRS. Within 1 cm: the LAS is exact (PROJ, point by point), the map's similarity
    // leaves out the Earth's curvature under a point h above the origin's plane, d from it
    // (h d / R: 131 m x 150 m / 6371 km = 3 mm here), and the file stores millimetres.
    io::LasHeader las_header;
    const std::vector<io::LasPoint> las = io::readLas(dir + "/objects/" + f[11], &las_header);
    ASSERT_EQ(las.size(), n) << line;
    double mx = 0, my = 0;
    for (const io::LasPoint& p : las) mx += p.x, my += p.y;
    EXPECT_NEAR(mx / n, std::stod(f[7]), 0.01) << line;
    EXPECT_NEAR(my / n, std::stod(f[8]), 0.01) << line;
    EXPECT_EQ(las_header.wkt.empty(), false) << line;
    las_wkt = las_header.wkt;
    const auto cloud = io::readGaussians(dir + "/objects/" + f[10]);
    ASSERT_EQ(cloud.size(), n) << line;
    double sx = 0, sy = 0, sz = 0;
    for (const GaussianPoint& p : cloud) {
      EXPECT_EQ(p.label, static_cast<std::uint32_t>(cls)) << line;
      EXPECT_GE(p.opacity, std::log(0.05f / 0.95f)) << line;  // opacity >= 0.05 (a logit)
      sx += p.x, sy += p.y, sz += p.z;
    }
    EXPECT_NEAR(std::stod(f[4]), sx / n, 1e-3) << line;
    EXPECT_NEAR(std::stod(f[5]), sy / n, 1e-3) << line;
    EXPECT_NEAR(std::stod(f[6]), sz / n, 1e-3) << line;
    ++files, gaussians += n;
    const auto polygon = polygons.find(id);
    if (polygon == polygons.end()) continue;  // under four cells: no polygon
    const auto& b = polygon->second;
    EXPECT_EQ(b[0], cls) << line;
    const double x = std::stod(f[7]), y = std::stod(f[8]);
    EXPECT_GE(x, b[1] - gsd) << line;  // within a cell (the polygons are simplified to one)
    EXPECT_LE(x, b[2] + gsd) << line;
    EXPECT_GE(y, b[3] - gsd) << line;
    EXPECT_LE(y, b[4] + gsd) << line;
    ++checked;
  }
  for (const auto& [id, box] : polygons) EXPECT_EQ(ids.count(id), 1u) << id;
  EXPECT_EQ(j["object_clouds"]["files"].get<std::size_t>(), files);
  EXPECT_EQ(j["object_clouds"]["gaussians"].get<std::size_t>(), gaussians);
  for (const char* ext : {".pcd", ".las"}) {
    EXPECT_EQ(
        io::filesIn(dir + "/objects", [&](const std::string& f) { return io::endsWith(f, ext); })
            .size(),
        files)
        << ext;
  }
  // The LAS files' CRS is the map's: UTM where the run is georeferenced, else local metres.
  const std::string tif_crs = gdalinfo(dir + "/classes.tif");
  if (tif_crs.find("UTM zone") != std::string::npos) {
    EXPECT_NE(las_wkt.find("UTM zone"), std::string::npos) << las_wkt;
  } else {
    EXPECT_NE(las_wkt.find("LOCAL_CS"), std::string::npos) << las_wkt;
  }
  *checked_out = checked;
}

TEST_F(MapProducts, AGeoreferencedRunMapsOntoItsUtmZone) {
  std::string out;
  const std::string dir = dir_->file("geo_ortho");
  ASSERT_EQ(
      test::runCommand(
          kCli + " ortho " + geoRun() +
              " --gsd 2 --vectors building,road --object-clouds --object-min-opacity 0.05 --out " +
              dir,
          &out),
      0)
      << out;
  const std::string info = gdalinfo(dir + "/classes.tif");
  EXPECT_NE(info.find("WGS 84 / UTM zone 15N"), std::string::npos) << info;
  EXPECT_NE(info.find("ID[\"EPSG\",32615]"), std::string::npos) << info;
  // The polygons of two classes, read by OGR's ogrinfo (gdal-bin): in the same CRS, as many as
  // ortho.json says, each named by its class, no larger in total than the classes' cells.
  std::string vectors;
  ASSERT_EQ(test::runCommand("ogrinfo -so -al " + dir + "/vectors.gpkg", &vectors), 0) << vectors;
  EXPECT_NE(vectors.find("Layer name: classes"), std::string::npos) << vectors;
  EXPECT_NE(vectors.find("UTM zone 15N"), std::string::npos) << vectors;
  EXPECT_NE(vectors.find("area_m2: Real"), std::string::npos) << vectors;
  EXPECT_NE(vectors.find("object_id: Integer"), std::string::npos) << vectors;
  EXPECT_NE(vectors.find("height_m: Real"), std::string::npos) << vectors;
  const nlohmann::json ortho = nlohmann::json::parse(test::readFile(dir + "/ortho.json"));
  const int polygons = ortho["vectors"]["polygons"].get<int>();
  EXPECT_GT(polygons, 0);
  EXPECT_NE(vectors.find("Feature Count: " + std::to_string(polygons)), std::string::npos)
      << vectors;
  std::string sums;
  ASSERT_EQ(test::runCommand("ogrinfo -q -sql \"SELECT class, SUM(area_m2) AS a FROM classes "
                             "GROUP BY class\" " +
                                 dir + "/vectors.gpkg",
                             &sums),
            0)
      << sums;
  EXPECT_NE(sums.find("class (String) = building"), std::string::npos) << sums;
  // Every polygon OGC-valid as GEOS checks it.
  std::string validity;
  ASSERT_EQ(test::runCommand("ogrinfo -q -dialect SQLite -sql \"SELECT COUNT(*) - "
                             "SUM(ST_IsValid(geom)) AS invalid FROM classes\" " +
                                 dir + "/vectors.gpkg 2>&1",
                             &validity),
            0)
      << validity;
  EXPECT_NE(validity.find("invalid (Integer) = 0"), std::string::npos) << validity;
  EXPECT_EQ(sums.find("class (String) = tree"), std::string::npos) << sums;
  // The objects' Gaussians (in the model's frame) lie over their polygons (in UTM).
  int checked = 0;
  checkObjectClouds(dir, classesOf(geoRun()), {"building", "road"}, 2.0, &checked);
  EXPECT_GT(checked, 0);
  // The grid holds the origin's UTM position (the scene's frame is centred near its origin).
  const auto origin_utm = geo::enuToUtm(
      io::georeferenceFromJson(test::readFile(geoRun() + "/georeference.json"), "g"), {{0, 0, 0}});
  std::string located;
  ASSERT_EQ(test::runCommand("gdallocationinfo -geoloc -valonly " + dir + "/classes.tif " +
                                 std::to_string(origin_utm[0][0]) + " " +
                                 std::to_string(origin_utm[0][1]),
                             &located),
            0)
      << located;
  EXPECT_FALSE(located.empty());
  // The LAS of the model: the same points, classes and CRS as the model.
  ASSERT_EQ(
      test::runCommand(kCli + " convert " + geoRun() + "/model.ply " + dir + "/model.las", &out), 0)
      << out;
  io::LasHeader header;
  const auto points = io::readLas(dir + "/model.las", &header);
  const auto model = io::readGaussians(geoRun() + "/model.ply");
  ASSERT_EQ(points.size(), model.size());
  EXPECT_NE(header.wkt.find("UTM zone 15N"), std::string::npos);
  const auto classes = classesOf(geoRun());
  std::vector<std::string> names;
  for (const auto& c : classes) names.push_back(c.name);
  const auto codes = io::asprsCodes(names);
  for (std::size_t i = 0; i < points.size(); i += 37) {
    ASSERT_LT(model[i].label, codes.size());
    EXPECT_EQ(points[i].classification, codes[model[i].label]);
    EXPECT_NEAR(points[i].z, model[i].z + 200.0, 0.05);  // origin altitude + up
  }
  EXPECT_NEAR(points[0].x, origin_utm[0][0] + model[0].x, 2.0);  // ENU ~ UTM, within 1 km
}

// `ortho --object-clouds`: each map object's Gaussians in objects/, with the ids of
// vectors.gpkg: of the object's class, opaque, their centroid over the object's polygon, counted
// alike in objects.csv, ortho.json and the files.
TEST_F(MapProducts, OrthoObjectCloudsHoldTheGaussiansOverEachObject) {
  std::string out;
  EXPECT_NE(test::runCommand(kCli + " ortho " + run() + " --gsd 0.5 --object-clouds --out " +
                                 dir_->file("no_vectors"),
                             &out),
            0);
  EXPECT_NE(out.find("--object-clouds"), std::string::npos) << out;
  EXPECT_NE(out.find("--vectors"), std::string::npos) << out;
  EXPECT_NE(test::runCommand(kCli + " ortho " + run() +
                                 " --gsd 0.5 --vectors building --object-clouds "
                                 "--object-min-opacity 1 --out " +
                                 dir_->file("no_vectors"),
                             &out),
            0);
  EXPECT_NE(out.find("--object-min-opacity"), std::string::npos) << out;
  // (The test's briefly trained model has few opaque Gaussians: the translucent ones too.)
  const std::string dir =
      ortho("--vectors building,tree --object-clouds --object-min-opacity 0.05", "object_clouds");
  int checked = 0;
  checkObjectClouds(dir, classesOf(run()), {"building", "tree"}, 0.5, &checked);
  EXPECT_GT(checked, 0);
}

TEST_F(MapProducts, ExtractWritesOneClassAsLasWithAMapOverride) {
  std::string out;
  test::writeFile(dir_->file("map.json"), "{\"road\": 77}");
  ASSERT_EQ(test::runCommand(kCli + " extract " + run() + " --class road --out " +
                                 dir_->file("roads.las") + " --classification-map " +
                                 dir_->file("map.json"),
                             &out),
            0)
      << out;
  io::LasHeader header;
  const auto points = io::readLas(dir_->file("roads.las"), &header);
  ASSERT_FALSE(points.empty());
  for (const auto& p : points) ASSERT_EQ(p.classification, 77);
  EXPECT_NE(header.wkt.find("LOCAL_CS"), std::string::npos);  // no georeference: local metres
  // A map naming a class the model does not have is an error naming the map file.
  test::writeFile(dir_->file("bad_map.json"), "{\"boat\": 70}");
  EXPECT_EQ(test::runCommand(kCli + " convert " + run() + "/model.ply " + dir_->file("x.las") +
                                 " --classification-map " + dir_->file("bad_map.json"),
                             &out),
            1);
  EXPECT_NE(out.find("bad_map.json"), std::string::npos) << out;
}

// `synth --out` writes the world's truth for other tools: the true DSM on the map-truth grid,
// the buildings' footprints (GDAL's ogrinfo reads them; one per standing building of the world)
// and the top surface's samples with class and instance.
TEST_F(MapProducts, SynthWritesTheWorldsTruthForOtherTools) {
  const std::string scene = dir_->file("scene");
  const std::string dsm = gdalinfo(scene + "/truth_dsm.tif");
  EXPECT_NE(dsm.find("Size is 800, 800"), std::string::npos) << dsm;
  EXPECT_NE(dsm.find("NoData Value=-9999"), std::string::npos) << dsm;
  std::string buildings;
  ASSERT_EQ(test::runCommand("ogrinfo -so -al " + scene + "/truth_buildings.gpkg", &buildings), 0)
      << buildings;
  const synth::World world(synth::SceneKind::kCity, 0);
  const auto footprints = synth::groundFootprints(world, 0);
  EXPECT_NE(buildings.find("Feature Count: " + std::to_string(footprints.size())),
            std::string::npos)
      << buildings;
  EXPECT_NE(buildings.find("height_m: Real"), std::string::npos) << buildings;
  std::ifstream ply(scene + "/truth_surface.ply");
  std::string line;
  std::size_t declared = 0, rows = 0;
  bool body = false;
  int buildings_seen = 0;
  while (std::getline(ply, line)) {
    if (body) {
      ++rows;
      std::istringstream f(line);
      double x, y, z;
      int cls, instance;
      ASSERT_TRUE(f >> x >> y >> z >> cls >> instance) << line;
      if (cls == 0) buildings_seen += instance >= 0;
      ASSERT_TRUE(cls != 0 || instance >= 0) << line;  // a building sample names its object
    } else if (line.rfind("element vertex ", 0) == 0) {
      declared = std::stoul(line.substr(15));
    } else if (line == "end_header") {
      body = true;
    }
  }
  EXPECT_EQ(rows, declared);
  EXPECT_EQ(declared, 160000u);  // 200 m at 0.5 m, all in the labelled area
  EXPECT_GT(buildings_seen, 1000);
}

TEST_F(MapProducts, EvalOrthoScoresTheClassMapAgainstTheSynthTruth) {
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " eval " + run() + " --ortho", &out), 0) << out;
  EXPECT_NE(out.find("\"cells\": 640000"), std::string::npos) << out;  // 200 m at 0.25 m
  EXPECT_NE(out.find("\"miou\""), std::string::npos) << out;
  EXPECT_TRUE(io::pathExists(run() + "/ortho_metrics.json"));
  // The DSM against the world's true top surface (ortho_truth.json names the world), all cells
  // and per class.
  const nlohmann::json j = nlohmann::json::parse(test::readFile(run() + "/ortho_metrics.json"));
  ASSERT_TRUE(j.contains("dsm")) << out;
  EXPECT_GT(j["dsm"]["cells"].get<int>(), 100000) << out;
  EXPECT_GT(j["dsm"]["rmse_m"].get<double>(), 0.0);
  EXPECT_LE(j["dsm"]["median_abs_m"].get<double>(), j["dsm"]["rmse_m"].get<double>() * 3);
  EXPECT_TRUE(j["dsm"]["per_class"]["building"].contains("rmse_m")) << out;
  // Away from the walls (the height steps) some cells remain, and the robust spread is there.
  EXPECT_GT(j["dsm"]["off_step_cells"].get<int>(), 0) << out;
  EXPECT_LT(j["dsm"]["off_step_cells"].get<int>(), j["dsm"]["cells"].get<int>()) << out;
  EXPECT_GT(j["dsm"]["nmad_m"].get<double>(), 0.0) << out;
  // The confusion matrix agrees with the areas and the IoUs it is the source of: a row and its
  // nodata cells are the true class's cells, a column the mapped class's cells.
  const nlohmann::json& cm = j["confusion"];
  const auto classes = cm["classes"].get<std::vector<std::string>>();
  ASSERT_EQ(cm["cells"].size(), classes.size()) << out;
  const double cell_m2 = 0.25 * 0.25;
  std::int64_t all = 0;
  for (std::size_t t = 0; t < classes.size(); ++t) {
    std::int64_t row = 0, column = 0;
    for (std::size_t p = 0; p < classes.size(); ++p) {
      row += cm["cells"][t][p].get<std::int64_t>();
      column += cm["cells"][p][t].get<std::int64_t>();
    }
    all += row + cm["nodata_cells"][t].get<std::int64_t>();
    const nlohmann::json& a = j["area"][classes[t]];
    EXPECT_DOUBLE_EQ((row + cm["nodata_cells"][t].get<std::int64_t>()) * cell_m2,
                     a["truth_m2"].get<double>())
        << classes[t];
    EXPECT_DOUBLE_EQ(row * cell_m2, a["truth_covered_m2"].get<double>()) << classes[t];
    EXPECT_DOUBLE_EQ(column * cell_m2, a["predicted_m2"].get<double>()) << classes[t];
    const std::int64_t tp = cm["cells"][t][t].get<std::int64_t>();
    if (row + column > 0) {
      EXPECT_NEAR(double(tp) / double(row + column - tp),
                  j["per_class_iou"][classes[t]].get<double>(), 1e-12)
          << classes[t];
    }
  }
  EXPECT_EQ(all, j["cells"].get<std::int64_t>());
  // The class map near the grid's centre: three discs, the largest the widest.
  ASSERT_EQ(j["miou_within"].size(), 3u) << out;
  EXPECT_DOUBLE_EQ(j["miou_within"][0]["radius_m"].get<double>(), 50.0);
  EXPECT_DOUBLE_EQ(j["miou_within"][2]["radius_m"].get<double>(), 90.0);
  for (const auto& w : j["miou_within"]) {
    EXPECT_GT(w["miou"].get<double>(), 0.0);
    EXPECT_LE(w["miou"].get<double>(), 1.0);
  }
  EXPECT_EQ(j["height_from"], "first");
  EXPECT_EQ(j["class_from"], "views");  // the default since 2026-12-01
  // The trim (default auto: the model's building class) and what it changed.
  EXPECT_EQ(j["trim"], nlohmann::json::array({"building"}));
  EXPECT_GE(j["trimmed_share"].get<double>(), 0.0);
  EXPECT_LT(j["trimmed_share"].get<double>(), 0.5);
  EXPECT_EQ(j["trim_whole_under"], 0);
  // Objects with too few Gaussians trimmed whole: never fewer cells trimmed (this briefly trained
  // model's objects have few opaque Gaussians: every one of them goes).
  ASSERT_EQ(test::runCommand(kCli + " eval " + run() + " --ortho --trim-whole-under 20 > /dev/null",
                             &out),
            0)
      << out;
  const nlohmann::json whole = nlohmann::json::parse(test::readFile(run() + "/ortho_metrics.json"));
  EXPECT_EQ(whole["trim_whole_under"], 20);
  EXPECT_GE(whole["trimmed_share"].get<double>(), j["trimmed_share"].get<double>());
  EXPECT_LE(whole["area"]["building"]["predicted_m2"].get<double>(),
            j["area"]["building"]["predicted_m2"].get<double>());
  EXPECT_NE(test::runCommand(kCli + " eval " + run() + " --ortho --trim-whole-under -1", &out), 0);
  EXPECT_NE(out.find("--trim-whole-under"), std::string::npos) << out;
  EXPECT_NE(test::runCommand(kCli + " eval " + run() + " --ortho --trim roofs", &out), 0);
  EXPECT_NE(out.find("--trim"), std::string::npos) << out;
  EXPECT_NE(out.find("roofs"), std::string::npos) << out;
  EXPECT_EQ(j["min_views"], 0);
  // Building objects of the map, cut at the default DSM step and at six steps (0: the plain
  // regions); cutting never makes fewer objects than the plain regions, and every count is
  // bounded by the true and predicted objects.
  ASSERT_TRUE(j.contains("objects")) << out;
  EXPECT_DOUBLE_EQ(j["objects"]["object_step_m"].get<double>(), 1.5);
  ASSERT_EQ(j["objects_by_step"].size(), 6u) << out;
  EXPECT_DOUBLE_EQ(j["objects_by_step"][0]["object_step_m"].get<double>(), 0.0);
  EXPECT_EQ(j["objects_by_step"][3], j["objects"]);
  EXPECT_GT(j["objects"]["true"].get<int>(), 10) << out;
  for (const auto& o : j["objects_by_step"]) {
    EXPECT_EQ(o["true"], j["objects"]["true"]);
    EXPECT_LE(o["matched"].get<int>(), o["predicted"].get<int>());
    EXPECT_LE(o["matched"].get<int>(), o["true"].get<int>());
  }
  EXPECT_GE(j["objects_by_step"][5]["predicted"].get<int>(),
            j["objects_by_step"][0]["predicted"].get<int>());
  // The cloud's building objects grouped by the map's (ortho --object-clouds), for each step.
  ASSERT_TRUE(j.contains("cloud_objects")) << out;
  EXPECT_EQ(j["cloud_objects"]["true"], j["objects"]["true"]);
  EXPECT_DOUBLE_EQ(j["cloud_objects"]["f1"].get<double>(), j["objects"]["cloud_f1"].get<double>());
  EXPECT_LE(j["cloud_objects"]["matched"].get<int>(), j["cloud_objects"]["predicted"].get<int>());
  for (const auto& o : j["objects_by_step"]) EXPECT_TRUE(o.contains("cloud_f1")) << o.dump();
  // The matched objects' heights against the true buildings' tops, one error per match.
  for (const char* key : {"height_m", "height_above_ground_m"}) {
    EXPECT_EQ(j["objects"][key]["objects"], j["objects"]["matched"]) << key;
    if (j["objects"]["matched"].get<int>() == 0) continue;
    EXPECT_GE(j["objects"][key]["median_abs_error"].get<double>(), 0.0) << key;
    EXPECT_GE(j["objects"][key]["rmse"].get<double>(),
              j["objects"][key]["median_abs_error"].get<double>() * 0.5)
        << key;
  }
  // A negative step is an error naming the flag.
  EXPECT_NE(test::runCommand(kCli + " eval " + run() + " --ortho --object-step -1", &out), 0);
  EXPECT_NE(out.find("--object-step"), std::string::npos) << out;
}

// `extract --raised-check`: a run's building Gaussians without those at ground height (a
// subset of the plain extraction); a file or a share outside [0, 1] is an error naming the flag.
TEST_F(MapProducts, ExtractRaisedCheckLeavesOutBuildingGaussiansAtGroundHeight) {
  test::TempDir dir;
  std::string out, checked_out;
  ASSERT_EQ(
      test::runCommand(
          kCli + " extract " + run() + " --class building --out " + dir.file("plain.ply"), &out),
      0)
      << out;
  ASSERT_EQ(test::runCommand(kCli + " extract " + run() + " --class building --raised-check 0.5 " +
                                 "--out " + dir.file("checked.ply"),
                             &checked_out),
            0)
      << checked_out;
  EXPECT_NE(checked_out.find("raised-class check (0.5)"), std::string::npos) << checked_out;
  const auto plain = io::readGaussians(dir.file("plain.ply"));
  const auto checked = io::readGaussians(dir.file("checked.ply"));
  EXPECT_LE(checked.size(), plain.size());
  std::size_t found = 0;  // every checked Gaussian is one of the plain extraction's
  for (const auto& c : checked) {
    for (const auto& p : plain) {
      if (p.x == c.x && p.y == c.y && p.z == c.z) {
        ++found;
        break;
      }
    }
  }
  EXPECT_EQ(found, checked.size());
  EXPECT_EQ(test::runCommand(kCli + " extract " + run() + " --class building --raised-check 2 " +
                                 "--out " + dir.file("x.ply"),
                             &out),
            1);
  EXPECT_NE(out.find("--raised-check"), std::string::npos) << out;
  EXPECT_EQ(test::runCommand(kCli + " extract " + dir.file("plain.ply") +
                                 " --class 0 --raised-check 0.33 --out " + dir.file("y.ply"),
                             &out),
            1);
  EXPECT_NE(out.find("a run directory"), std::string::npos) << out;
}

TEST_F(MapProducts, EvalThreeDScoresTheCloudAgainstTheWorldsSurfaces) {
  std::string out;
  ASSERT_EQ(test::runCommand(kCli + " eval " + run() + " --3d", &out), 0) << out;
  const nlohmann::json j = nlohmann::json::parse(test::readFile(run() + "/metrics_3d.json"));
  EXPECT_EQ(j["truth"].get<std::string>().rfind("synth:city:", 0), 0u) << j.dump();
  EXPECT_GT(j["gaussians"].get<int>(), 100);
  EXPECT_GT(j["scored"].get<int>(), 0);
  EXPECT_LE(j["scored"].get<int>(), j["gaussians"].get<int>());
  for (const char* key : {"point_miou", "point_oacc", "weighted_miou", "share_within_0.5_m",
                          "share_beyond_1.0_m", "completeness_all"}) {
    EXPECT_GE(j[key].get<double>(), 0.0) << key;
    EXPECT_LE(j[key].get<double>(), 1.0) << key;
  }
  // This short run has few opaque Gaussians (if any); every Gaussian's distance is there.
  EXPECT_GT(j["distance_median_all_m"].get<double>(), 0.0) << j.dump();
  EXPECT_LE(j["distance_median_all_m"].get<double>(), j["distance_p90_all_m"].get<double>());
  EXPECT_LE(j["distance_median_m"].get<double>(), j["distance_p90_m"].get<double>());
  EXPECT_TRUE(j["point_iou"].contains("building")) << j.dump();
  // Over the map's area only: a part of the cloud, in the labelled world's square.
  ASSERT_TRUE(j.contains("over_map")) << j.dump();
  const nlohmann::json& over = j["over_map"];
  ASSERT_EQ(over["bounds"].size(), 4u) << over.dump();
  EXPECT_LT(over["bounds"][0].get<double>(), over["bounds"][2].get<double>());
  EXPECT_LT(over["bounds"][1].get<double>(), over["bounds"][3].get<double>());
  EXPECT_GT(over["gaussians"].get<int>(), 0) << over.dump();
  EXPECT_LE(over["gaussians"].get<int>(), j["gaussians"].get<int>());
  EXPECT_LE(over["opaque"].get<int>(), j["opaque"].get<int>());
  for (const char* key : {"share_within_0.5_m", "share_beyond_1.0_m", "point_miou"}) {
    EXPECT_GE(over[key].get<double>(), 0.0) << key;
    EXPECT_LE(over[key].get<double>(), 1.0) << key;
  }
  // Buildings as objects: the world's standing buildings are the truth (a city has dozens).
  ASSERT_TRUE(j.contains("objects")) << j.dump();
  EXPECT_GT(j["objects"]["true"].get<int>(), 10) << j.dump();
  EXPECT_LE(j["objects"]["matched"].get<int>(), j["objects"]["true"].get<int>());
  EXPECT_LE(j["objects"]["matched"].get<int>(), j["objects"]["predicted"].get<int>());
  // The example's automatic tolerance: 4 x the building Gaussians' spacing, at least 1 m.
  EXPECT_NEAR(j["objects"]["cluster_tolerance_m"].get<double>(),
              std::max(1.0, 4 * j["building_spacing_m"].get<double>()), 1e-9);
  EXPECT_EQ(j["objects_tolerance_1m"]["cluster_tolerance_m"].get<double>(), 1.0);
  EXPECT_EQ(j["objects_raised_check"]["true"], j["objects"]["true"]);
  ASSERT_EQ(j["objects_by_spacing"].size(), 5u);
  for (const auto& entry : j["objects_by_spacing"]) {
    EXPECT_GE(entry["cluster_tolerance_m"].get<double>(), 1.0) << entry.dump();
    EXPECT_LE(entry["f1_raised_check"].get<double>(), 1.0) << entry.dump();
  }
  // The cloud `extract --on-surface M` hands out, for three M: more kept as M grows.
  ASSERT_EQ(j["on_surface"].size(), 3u) << j.dump();
  std::int64_t previous = 0;
  for (const auto& entry : j["on_surface"]) {
    EXPECT_GE(entry["gaussians"].get<std::int64_t>(), previous) << entry.dump();
    EXPECT_LE(entry["gaussians"].get<std::int64_t>(), j["gaussians"].get<std::int64_t>());
    previous = entry["gaussians"].get<std::int64_t>();
    EXPECT_GE(entry["objects_f1"].get<double>(), 0.0);
    EXPECT_LE(entry["objects_f1"].get<double>(), 1.0);
  }
  // A scene that names no generated world has no 3D truth: one line.
  EXPECT_EQ(test::runCommand(kCli + " eval " + run() + " --3d --ortho", &out), 1) << out;
  // --scene: the scene the run is scored on (a run copied away from its scene; a scene directory
  // is imported at eval's scale, 0.5, so the classes voted from its views may differ): the same
  // Gaussians are scored; a missing scene is named.
  ASSERT_EQ(
      test::runCommand(kCli + " eval " + run() + " --3d --scene " + dir_->file("scene"), &out), 0)
      << out;
  EXPECT_EQ(nlohmann::json::parse(test::readFile(run() + "/metrics_3d.json"))["gaussians"],
            j["gaussians"]);
  EXPECT_EQ(test::runCommand(kCli + " eval " + run() + " --3d --scene " + dir_->file("gone"), &out),
            1);
  EXPECT_NE(out.find(dir_->file("gone")), std::string::npos) << out;
  EXPECT_EQ(
      test::runCommand(kCli + " eval " + run() + " --ortho --scene " + dir_->file("gone"), &out),
      1);
  EXPECT_NE(out.find(dir_->file("gone")), std::string::npos) << out;
}

TEST_F(MapProducts, BadOptionsAreOneLineErrors) {
  auto expectError = [&](const std::string& args, const std::string& needle) {
    std::string out;
    EXPECT_EQ(test::runCommand(kCli + " " + args, &out), 1) << args << "\n" << out;
    EXPECT_NE(out.find(needle), std::string::npos) << args << "\n" << out;
    EXPECT_EQ(std::count(out.begin(), out.end(), '\n'), 1) << out;
  };
  expectError("ortho " + run() + " --gsd 0 --out " + dir_->file("x"), "--gsd");
  expectError("ortho " + run() + " --gsd -2 --out " + dir_->file("x"), "--gsd");
  expectError("ortho " + run() + " --gsd 0.0001 --out " + dir_->file("x"), "40000");
  expectError("ortho " + run() + " --bounds 5000,5000,5100,5100 --out " + dir_->file("x"),
              "footprint");
  expectError("ortho " + run() + " --bounds 10,10,0,20 --out " + dir_->file("x"), "--bounds");
  expectError("ortho " + run() + " --height top --out " + dir_->file("x"), "--height");
  expectError("ortho " + run() + " --class-from top --out " + dir_->file("x"), "--class-from");
  expectError("ortho " + run() + " --height views --out " + dir_->file("x"), "--height");
  expectError("ortho " + run() + " --min-views -1 --out " + dir_->file("x"), "--min-views");
  expectError("ortho " + run() + " --min-spread 400 --out " + dir_->file("x"), "--min-spread");
  expectError("ortho " + run() + " --vectors roof --out " + dir_->file("x"), "roof");
  expectError("ortho " + run() + " --on-surface -1 --out " + dir_->file("x"), "--on-surface");
  expectError("ortho " + run() + " --raised-check 1.5 --out " + dir_->file("x"), "--raised-check");
  expectError("ortho " + run() + " --ground-window 0 --out " + dir_->file("x"), "--ground-window");
  expectError("eval " + run() + " --ortho --raised-check -1", "--raised-check");
  expectError("eval " + run() + " --ortho --height top", "--height");
  expectError("render " + run() + " --views nope --out " + dir_->file("x"), "nope");
  expectError("render " + run() + " --outputs class,nope --out " + dir_->file("x"), "--outputs");
  expectError("render " + run() + " --size 0x5 --out " + dir_->file("x"), "--size");
  expectError("render " + run() + " --path spiral --out " + dir_->file("x"), "--path");
  expectError("ortho " + run() + " --gsd 2 --out /proc/sadsplat_cannot_write", "/proc/");
}

}  // namespace
}  // namespace sadsplat
