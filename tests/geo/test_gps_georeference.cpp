// The georeference from consumer GPS (geo::fitGpsGeoreference) on hand-made flights whose truth
// is known: an SfM frame that is a known similarity of the true east-north-up frame, GPS with the
// noise of a camera's own receiver (metres horizontally, altitudes wandering by tens of metres).
#include <gtest/gtest.h>

#include <Eigen/Dense>

#include <cmath>
#include <random>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/geodesy.h"
#include "sadsplat/geo/gps_georeference.h"

namespace sadsplat {
namespace {

using Vec3 = std::array<double, 3>;

struct Flight {
  std::vector<geo::GpsPhoto> photos;
  std::vector<Vec3> points;  // SfM frame
  Eigen::Matrix3d R;         // true ENU -> SfM: x_sfm = s R x_enu + t
  double s = 0.37;
  Eigen::Vector3d t{3, -7, 12};
};

Vec3 arr(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// A nadir grid (lines x per_line photos at `altitude` over [-90, 90] m), or an orbit of oblique
// views (pitch 45 degrees) when `orbit`; ground points on z = 0 with 20 % on roofs 5-20 m up.
// GPS: N(0, sigma) per horizontal axis, altitude + 30 m + a 25 m wander + N(0, 3).
Flight makeFlight(bool orbit, double sigma, std::uint32_t seed, double span = 90) {
  Flight f;
  f.R = Eigen::AngleAxisd(0.7, Eigen::Vector3d(0.3, -0.5, 0.8).normalized()).toRotationMatrix();
  std::mt19937 rng(seed);
  std::normal_distribution<double> noise(0, 1);
  std::uniform_real_distribution<double> uni(-1, 1);
  const auto toSfm = [&](const Eigen::Vector3d& x) { return Eigen::Vector3d(f.s * f.R * x + f.t); };
  std::vector<Eigen::Vector3d> centres, views;
  if (orbit) {
    for (int i = 0; i < 30; ++i) {
      const double a = 2 * M_PI * i / 30;
      const Eigen::Vector3d c(150 * std::cos(a), 150 * std::sin(a), 150);
      centres.push_back(c);
      views.push_back((Eigen::Vector3d(0, 0, 0) - c).normalized());
    }
  } else {
    for (int line = 0; line < 5; ++line) {
      for (int k = 0; k < 8; ++k) {
        centres.emplace_back(-span + line * 2 * span / 4, -span + k * 2 * span / 7, 120);
        // A gimbal within ~1 degree of straight down.
        views.push_back(Eigen::Vector3d(0.01 * uni(rng), 0.01 * uni(rng), -1).normalized());
      }
    }
  }
  for (std::size_t i = 0; i < centres.size(); ++i) {
    geo::GpsPhoto p;
    p.name = "p" + std::to_string(i);
    p.centre = arr(toSfm(centres[i]));
    p.viewing = arr(f.R * views[i]);
    p.gps = Vec3{centres[i].x() + sigma * noise(rng), centres[i].y() + sigma * noise(rng),
                 centres[i].z() + 30 + 25 * std::sin(0.3 * i) + 3 * noise(rng)};
    f.photos.push_back(p);
  }
  for (int i = 0; i < 3000; ++i) {
    const bool roof = i % 5 == 0;
    const Eigen::Vector3d x(100 * uni(rng), 100 * uni(rng), roof ? 5 + 15 * (uni(rng) + 1) / 2 : 0);
    f.points.push_back(arr(toSfm(x)));
  }
  return f;
}

// The fitted frame against the truth: tilt (degrees of the true up from z), heading (degrees)
// and the scale error (relative).
struct FrameError {
  double tilt, heading, scale;
};
FrameError frameError(const Flight& f, const io::Similarity& fit) {
  Eigen::Matrix3d Rf;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) Rf(r, c) = fit.rotation[3 * r + c];
  // ENU -> SfM -> fitted: x' = fit.scale * Rf (s R x + t) + ...: its rotation Rf R should be I.
  const Eigen::Matrix3d D = Rf * f.R;
  const Eigen::Vector3d up = D * Eigen::Vector3d::UnitZ();
  const Eigen::Vector3d east = D * Eigen::Vector3d::UnitX();
  return {std::acos(std::clamp(up.z(), -1.0, 1.0)) * 180 / M_PI,
          std::atan2(east.y(), east.x()) * 180 / M_PI, fit.scale * f.s - 1};
}

TEST(GpsGeoreference, ANadirFlightWithCameraGpsComesOutLevelAndInScale) {
  const Flight f = makeFlight(false, 2.0, 1);
  const geo::GpsFit fit = geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400});
  const io::Georeference& g = fit.georeference;
  const FrameError e = frameError(f, g.sfm_to_local);
  EXPECT_EQ(g.up_source, "nadir views");
  // 40 photos within ~1 degree of nadir: their mean is level to well under a degree.
  EXPECT_LT(e.tilt, 0.3);
  // Scale: the GPS noise (2 m) over the flight's spread (~72 m, 40 photos): 1 sigma ~0.4 %.
  EXPECT_LT(std::abs(e.scale), 0.01);
  EXPECT_LT(std::abs(e.heading), 1.0);
  // The GPS's own noise leaves a photo beyond 3.44 sigma 0.27 % of the time: (nearly) all agree.
  EXPECT_GE(g.inliers, 39);
  // The measured noise is the GPS's own (2 m per axis), not the default it started from.
  EXPECT_NEAR(g.gps_noise_metres, 2.0, 0.6);
  EXPECT_NEAR(g.horizontal_rms_metres, 2.0 * std::sqrt(2.0), 0.8);
  // The altitude wanders: a vertical RMS of metres to tens of metres, and no tilt from it.
  EXPECT_GT(g.vertical_rms_metres, 5);
  EXPECT_LT(g.ground_tilt_deg, 0.5);
  EXPECT_LT(g.views_tilt_deg, 0.3);
  EXPECT_TRUE(g.trustworthy()) << (g.doubts.empty() ? "" : g.doubts[0]);

  // The 3D similarity of the GPS alone, as sadsplat fitted it before, tilts this flight by
  // degrees: the test's noise is the kind that broke it.
  std::vector<Vec3> centres, targets;
  for (const auto& p : f.photos) centres.push_back(p.centre), targets.push_back(*p.gps);
  const io::Similarity old = geo::fitSimilarity(centres, targets, 5.0);
  EXPECT_GT(frameError(f, old).tilt, 2.0);
}

TEST(GpsGeoreference, AnOrbitOfObliqueViewsTakesUpFromTheGroundPlane) {
  const Flight f = makeFlight(true, 2.0, 2);
  const geo::UpCue views = [&] {
    std::vector<Vec3> v;
    for (const auto& p : f.photos) v.push_back(p.viewing);
    return geo::upFromViews(v);
  }();
  EXPECT_FALSE(views.found);  // 45-degree views: mean resultant length ~0.71
  EXPECT_NEAR(views.quality, std::cos(M_PI / 4), 0.02);
  const geo::GpsFit fit = geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400});
  EXPECT_EQ(fit.georeference.up_source, "ground plane");
  const FrameError e = frameError(f, fit.georeference.sfm_to_local);
  EXPECT_LT(e.tilt, 0.3);
  EXPECT_LT(std::abs(e.scale), 0.01);
  EXPECT_EQ(fit.georeference.views_tilt_deg, -1);
  EXPECT_LT(fit.georeference.ground_tilt_deg, 1e-6);
}

TEST(GpsGeoreference, PhotosFarFromTheirGpsAreOutliersAndTheNoiseIsMeasured) {
  Flight f = makeFlight(false, 1.0, 3);
  for (int i = 0; i < 40; i += 5) (*f.photos[i].gps)[0] += 40;  // 8 of 40 photos 40 m off
  const geo::GpsFit fit = geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400}, {4.0});
  EXPECT_EQ(fit.georeference.inliers, 32);
  for (int i = 0; i < 40; ++i) EXPECT_EQ(fit.residuals[i].inlier, i % 5 != 0) << i;
  EXPECT_NEAR(fit.georeference.gps_noise_metres, 1.0, 0.35);
  // 3.44x the measured noise, or the stated accuracy where that is more: 4 m, not RANSAC's
  // 13.8 m.
  EXPECT_DOUBLE_EQ(fit.georeference.inlier_metres, 4.0);
  f.photos[0].gps = Vec3{(*f.photos[0].gps)[0] - 40 + 2.0, (*f.photos[0].gps)[1], 0};
  const geo::GpsFit near = geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400}, {4.0});
  EXPECT_TRUE(near.residuals[0].inlier);  // ~2 m off: within the stated accuracy
  EXPECT_LT(frameError(f, fit.georeference.sfm_to_local).tilt, 0.3);
  EXPECT_TRUE(fit.georeference.trustworthy());
}

TEST(GpsGeoreference, DoubtsAreSaid) {
  // A flight of +-5 m against 10 m of GPS noise: the scale is not known.
  Flight small = makeFlight(false, 10.0, 4, 5.0);
  const geo::GpsFit fit = geo::fitGpsGeoreference(small.photos, small.points, {47, 8, 400});
  EXPECT_FALSE(fit.georeference.trustworthy());
  bool scale_doubt = false;
  for (const auto& d : fit.georeference.doubts) scale_doubt |= d.find("scale") != std::string::npos;
  EXPECT_TRUE(scale_doubt);

  // Neither nadir views nor a ground plane: the GPS alone gives the tilt, and that is said.
  Flight oblique = makeFlight(true, 0.5, 5);
  std::mt19937 rng(9);
  std::uniform_real_distribution<double> uni(-100, 100);
  for (auto& p : oblique.points) p = {uni(rng), uni(rng), uni(rng)};  // no plane
  const geo::GpsFit gps = geo::fitGpsGeoreference(oblique.photos, oblique.points, {47, 8, 400});
  EXPECT_EQ(gps.georeference.up_source, "gps 3D fit");
  EXPECT_FALSE(gps.georeference.trustworthy());

  // A GPS stated as 0.5 m that is 5 m noisy.
  Flight noisy = makeFlight(false, 5.0, 6);
  for (auto& p : noisy.photos) p.stated_accuracy = 0.5;
  const geo::GpsFit stated = geo::fitGpsGeoreference(noisy.photos, noisy.points, {47, 8, 400});
  EXPECT_DOUBLE_EQ(stated.georeference.gps_accuracy_metres, 0.5);
  bool noisier = false;
  for (const auto& d : stated.georeference.doubts)
    noisier |= d.find("noisier") != std::string::npos;
  EXPECT_TRUE(noisier);
}

TEST(GpsGeoreference, TooFewPhotosWithGpsIsAnError) {
  Flight f = makeFlight(false, 1.0, 7);
  for (std::size_t i = 2; i < f.photos.size(); ++i) f.photos[i].gps.reset();
  EXPECT_THROW(geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400}), Error);
}

TEST(GpsGeoreference, TheJsonKeepsWhatTheFitSaid) {
  const Flight f = makeFlight(false, 2.0, 8);
  const geo::GpsFit fit = geo::fitGpsGeoreference(f.photos, f.points, {47, 8, 400});
  io::Georeference g = fit.georeference;
  g.doubts = {"a doubt"};
  const io::Georeference back = io::georeferenceFromJson(io::georeferenceToJson(g), "<test>");
  EXPECT_EQ(back.up_source, "nadir views");
  EXPECT_DOUBLE_EQ(back.gps_noise_metres, g.gps_noise_metres);
  EXPECT_DOUBLE_EQ(back.ground_tilt_deg, g.ground_tilt_deg);
  EXPECT_DOUBLE_EQ(back.scale_uncertainty, g.scale_uncertainty);
  ASSERT_EQ(back.doubts.size(), 1u);
  EXPECT_FALSE(back.trustworthy());
  // Files of before: no such fields, nothing to doubt.
  const io::Georeference old = io::georeferenceFromJson(
      R"({"origin": {"latitude": 1, "longitude": 2, "altitude": 3}, "epsg_utm": 32631})", "<old>");
  EXPECT_TRUE(old.up_source.empty());
  EXPECT_TRUE(old.trustworthy());
  EXPECT_THROW(io::georeferenceFromJson(
                   R"({"origin": {"latitude": 1, "longitude": 2, "altitude": 3}, "epsg_utm": 32631,
                       "up_source": "ground plane", "doubts": [3]})",
                   "<bad>"),
               Error);
}

}  // namespace
}  // namespace sadsplat
