// Ground control points: OpenDroneMap's gcp_list.txt read and checked, points triangulated
// through distorted cameras, the georeference fitted to control points and checked on the others.
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <fstream>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/geodesy.h"
#include "sadsplat/geo/ground_control.h"
#include "sadsplat/geo/map_frame.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using Vec3 = std::array<double, 3>;

const io::GeoPosition kOrigin{47.3769, 8.5417, 420.0};

// Six nadir photos (SIMPLE_RADIAL, k = -0.08) over a 120 x 60 m area at 100 m, in an SfM frame
// that is the similarity x_sfm = 0.25 R x_enu + t of the east-north-up frame around kOrigin.
struct World {
  io::ColmapModel model;
  Eigen::Matrix3d R =
      Eigen::AngleAxisd(0.4, Eigen::Vector3d(1, 2, 3).normalized()).toRotationMatrix();
  double s = 0.25;
  Eigen::Vector3d t{1, 2, 3};
  World() {
    io::ColmapCamera cam;
    cam.id = 1;
    cam.model = io::CameraModel::kSimpleRadial;
    cam.width = 1000;
    cam.height = 750;
    cam.params = {600, 500, 375, -0.08};
    model.cameras.push_back(cam);
    for (int i = 0; i < 6; ++i) {
      const Eigen::Vector3d c_enu(-60 + 40.0 * (i % 4), i < 4 ? -20 : 20, 100);
      // Camera looking down: rows right = east, down = south, forward = -up.
      Eigen::Matrix3d rc;
      rc << 1, 0, 0, 0, -1, 0, 0, 0, -1;
      // In the SfM frame: x_cam = rc (x_enu - c) with x_enu = R^T (x_sfm - t) / s, scaled by s.
      const Eigen::Matrix3d r_sfm = rc * R.transpose();
      const Eigen::Vector3d c_sfm = s * R * c_enu + t;
      io::ColmapImage im;
      im.id = i + 1;
      im.camera_id = 1;
      im.name = "IMG_" + std::to_string(i) + ".JPG";
      const Eigen::Quaterniond q(r_sfm);
      im.qvec = {q.w(), q.x(), q.y(), q.z()};
      const Eigen::Vector3d tv = -r_sfm * c_sfm;
      im.tvec = {tv.x(), tv.y(), tv.z()};
      model.images.push_back(im);
    }
  }
  Vec3 toSfm(const Vec3& enu) const {
    const Eigen::Vector3d x = s * R * Eigen::Vector3d(enu[0], enu[1], enu[2]) + t;
    return {x.x(), x.y(), x.z()};
  }
  // The pixel of an ENU point in photo i (with the lens distortion), or false outside it.
  bool project(int i, const Vec3& enu, double* px, double* py) const {
    const auto& im = model.images[i];
    const Eigen::Matrix3d r =
        Eigen::Quaterniond(im.qvec[0], im.qvec[1], im.qvec[2], im.qvec[3]).toRotationMatrix();
    const Vec3 x = toSfm(enu);
    const Eigen::Vector3d c =
        r * Eigen::Vector3d(x[0], x[1], x[2]) + Eigen::Vector3d(im.tvec[0], im.tvec[1], im.tvec[2]);
    if (c.z() <= 0) return false;
    const double u = c.x() / c.z(), v = c.y() / c.z(), radial = 1 - 0.08 * (u * u + v * v);
    *px = 600 * u * radial + 500;
    *py = 600 * v * radial + 375;
    return *px >= 0 && *py >= 0 && *px < 1000 && *py < 750;
  }
};

std::vector<std::string> photoNames() {
  std::vector<std::string> names;
  for (int i = 0; i < 6; ++i) names.push_back("IMG_" + std::to_string(i) + ".JPG");
  return names;
}

// gcp_list.txt of `points` (ENU) in UTM 32N, marked on every photo that sees them.
std::string gcpText(const World& w, const std::vector<Vec3>& points, const std::string& crs_line,
                    const std::vector<std::string>& names) {
  io::Georeference g;
  g.origin = kOrigin;
  g.epsg_utm = 32632;
  const std::vector<Vec3> utm = geo::enuToUtm(g, points);
  std::ostringstream out;
  out.precision(12);
  out << crs_line << "\n";
  for (std::size_t k = 0; k < points.size(); ++k) {
    for (int i = 0; i < 6; ++i) {
      double px, py;
      if (!w.project(i, points[k], &px, &py)) continue;
      out << utm[k][0] << " " << utm[k][1] << " " << utm[k][2] << " " << px << " " << py << " "
          << w.model.images[i].name << " " << names[k] << "\n";
    }
  }
  return out.str();
}

std::vector<Vec3> groundPoints() {
  return {{-50, -10, 2}, {-20, 5, 0}, {0, -8, 1},   {15, 12, 3},
          {30, -5, 0},   {45, 8, 2},  {-35, 15, 1}, {5, 18, 0}};
}
std::vector<std::string> gcpNames() {
  return {"gcp1", "gcp2", "gcp3", "gcp4", "gcp5", "gcp6", "gcp7", "gcp8"};
}

TEST(GroundControl, ControlPointsFixTheFrameAndCheckPointsMeasureIt) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  test::TempDir tmp;
  const World w;
  const std::string path = tmp.file("gcp_list.txt");
  test::writeFile(path, gcpText(w, groundPoints(), "EPSG:32632", gcpNames()));
  const geo::GcpList list = geo::readGcpList(path, photoNames());
  ASSERT_EQ(list.points.size(), 8u);
  // 8 unmarked points: every 4th in name order is a check point (gcp4, gcp8).
  int checks = 0;
  for (const auto& p : list.points) {
    EXPECT_EQ(p.check, p.name == "gcp4" || p.name == "gcp8") << p.name;
    EXPECT_GE(p.observations.size(), 2u) << p.name;
    checks += p.check;
  }
  EXPECT_EQ(checks, 2);
  // Through PROJ and back: the WGS84 position is the one the ENU point came from (1 mm).
  const auto enu = geo::toEnu(list.points[0].wgs84, kOrigin);
  EXPECT_NEAR(enu[0], -50, 1e-3);
  EXPECT_NEAR(enu[1], -10, 1e-3);
  EXPECT_NEAR(enu[2], 2, 1e-3);

  const geo::TriangulatedGcp t = geo::triangulateGcp(w.model, list.points[1]);
  ASSERT_TRUE(t.ok) << t.why;
  const Vec3 truth = w.toSfm({-20, 5, 0});
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(t.sfm[k], truth[k], 1e-6);
  EXPECT_LT(t.reprojection_px, 1e-6);

  const geo::GcpFit fit = geo::fitGcpGeoreference(w.model, list, kOrigin);
  EXPECT_TRUE(fit.skipped.empty());
  const io::Georeference& g = fit.georeference;
  EXPECT_EQ(g.control_points, 6);
  EXPECT_EQ(g.check_points, 2);
  EXPECT_EQ(g.up_source, "ground control points");
  EXPECT_LT(g.check_rmse_horizontal, 2e-3);
  EXPECT_LT(g.check_rmse_vertical, 2e-3);
  EXPECT_NEAR(g.sfm_to_local.scale, 1 / w.s, 1e-5);

  // OpenDroneMap's "WGS84 UTM 32N" names the same CRS.
  test::writeFile(path, gcpText(w, groundPoints(), "WGS84 UTM 32N", gcpNames()));
  const geo::GcpList odm = geo::readGcpList(path, photoNames());
  EXPECT_NEAR(odm.points[0].wgs84.latitude, list.points[0].wgs84.latitude, 1e-12);
}

TEST(GroundControl, MarkedCheckPointsAreHeldOutAndAPerturbedOneShowsInTheCheck) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  test::TempDir tmp;
  const World w;
  std::vector<std::string> names = {"A", "B", "C", "CHK-1", "D"};
  const std::vector<Vec3> all = groundPoints();
  const std::vector<Vec3> points(all.begin(), all.begin() + 5);
  const std::string path = tmp.file("gcp_list.txt");
  test::writeFile(path,
                  gcpText(w, points, "+proj=utm +zone=32 +datum=WGS84 +units=m +no_defs", names));
  geo::GcpList list = geo::readGcpList(path);
  for (const auto& p : list.points) EXPECT_EQ(p.check, p.name == "CHK-1") << p.name;
  // The check point's surveyed height 0.5 m off: the check says 0.5 m, the controls stay exact.
  for (auto& p : list.points) {
    if (p.check) p.wgs84.altitude += 0.5;
  }
  const geo::GcpFit fit = geo::fitGcpGeoreference(w.model, list, kOrigin);
  EXPECT_NEAR(fit.georeference.check_rmse_vertical, 0.5, 2e-3);
  EXPECT_LT(fit.georeference.vertical_rms_metres, 2e-3);
}

// One bad thing per file, each a one-line error naming the file and what was expected.
TEST(GroundControl, BadFilesAreOneLineErrors) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  test::TempDir tmp;
  const World w;
  const std::string good = gcpText(w, groundPoints(), "EPSG:32632", gcpNames());
  const std::string body = good.substr(good.find('\n') + 1);
  const std::string path = tmp.file("gcp_list.txt");
  const auto expectError = [&](const std::string& text, const std::string& needle) {
    test::writeFile(path, text);
    try {
      geo::readGcpList(path, photoNames());
      ADD_FAILURE() << "no error for " << needle;
    } catch (const Error& e) {
      const std::string m = e.what();
      EXPECT_NE(m.find(path), std::string::npos) << m;
      EXPECT_NE(m.find(needle), std::string::npos) << m;
      EXPECT_EQ(m.find('\n'), std::string::npos) << m;
    }
  };
  expectError("EPSG:999999\n" + body, "CRS");
  expectError("not a crs at all\n" + body, "CRS");
  expectError("", "CRS");
  expectError("EPSG:32632\n" + body + "1 2 3 4 5 IMG_9.JPG gcp9\n1 2 3 4 5 IMG_0.JPG gcp9\n",
              "a photo of the photo folder");
  expectError("EPSG:32632\n" + body + "465000 5247000 400 10 10 IMG_0.JPG lonely\n",
              "at least 2 photos");
  expectError("EPSG:32632\n" + body + "465000 nan 400 10 10 IMG_0.JPG x\n", "line");
  expectError("EPSG:32632\n" + body + "465000 5247000 400 10\n", "x y z px py image");
  expectError(
      "EPSG:32632\n465000 5247000 400 10 10 IMG_0.JPG a\n465000 5247000 400 10 10 "
      "IMG_1.JPG a\n",
      "at least 3 control points");
}

TEST(GroundControl, PointsTheReconstructionCannotPlaceAreSkippedWithWhy) {
  if (!geo::haveGdal()) GTEST_SKIP() << "built without GDAL";
  test::TempDir tmp;
  World w;
  const std::string path = tmp.file("gcp_list.txt");
  test::writeFile(path, gcpText(w, groundPoints(), "EPSG:32632", gcpNames()));
  const geo::GcpList list = geo::readGcpList(path, photoNames());
  // Only IMG_0 registered: no point has two marks on registered photos.
  w.model.images.resize(1);
  try {
    geo::fitGcpGeoreference(w.model, list, kOrigin);
    ADD_FAILURE() << "no error";
  } catch (const Error& e) {
    const std::string m = e.what();
    EXPECT_NE(m.find("at least 3 triangulated"), std::string::npos) << m;
    EXPECT_NE(m.find("registered photos (2 needed)"), std::string::npos) << m;
    EXPECT_NE(m.find(path), std::string::npos) << m;
  }
}

}  // namespace
}  // namespace sadsplat
