// WGS84 geodesy (geo/geodesy.h): east-north-up metres, UTM zones, the robust similarity fit.
#include <gtest/gtest.h>

#include <cmath>
#include <random>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/geodesy.h"

namespace sadsplat {
namespace {

TEST(Geodesy, EastNorthUpIsMetresAroundTheOrigin) {
  const io::GeoPosition origin{46.843, -91.994, 198.6};
  // One arc-second of latitude is ~30.9 m here; 0.001 degree of longitude ~76 m at 46.8 N.
  const auto north = geo::toEnu({origin.latitude + 1.0 / 3600, origin.longitude, 198.6}, origin);
  EXPECT_NEAR(north[0], 0.0, 1e-6);
  EXPECT_NEAR(north[1], 30.88, 0.05);
  EXPECT_NEAR(north[2], 0.0, 1e-3);  // the ellipsoid's curvature over 31 m: < 0.1 mm
  const auto east = geo::toEnu({origin.latitude, origin.longitude + 0.001, 198.6}, origin);
  EXPECT_NEAR(east[0], 111320 * std::cos(origin.latitude * M_PI / 180) * 0.001, 0.3);
  EXPECT_NEAR(east[1], 0.0, 0.01);
  const auto up = geo::toEnu({origin.latitude, origin.longitude, 298.6}, origin);
  EXPECT_NEAR(up[2], 100.0, 1e-6);
  // The inverse, to a millimetre.
  const io::GeoPosition back = geo::fromEnu({123.4, -567.8, 42.0}, origin);
  const auto again = geo::toEnu(back, origin);
  EXPECT_NEAR(again[0], 123.4, 1e-3);
  EXPECT_NEAR(again[1], -567.8, 1e-3);
  EXPECT_NEAR(again[2], 42.0, 1e-3);
}

TEST(Geodesy, TheEnuToEcefMatrixPlacesPointsToAMillimetre) {
  // On the equator at the prime meridian, ENU (e, n, u) is ECEF (a + u, e, n).
  const auto m0 = geo::enuToEcefMatrix({0, 0, 0});
  EXPECT_NEAR(m0[12], 6378137.0, 1e-6);
  EXPECT_NEAR(m0[0 * 4 + 1], 1.0, 1e-12);  // east column: +y
  EXPECT_NEAR(m0[1 * 4 + 2], 1.0, 1e-12);  // north column: +z
  EXPECT_NEAR(m0[2 * 4 + 0], 1.0, 1e-12);  // up column: +x
  EXPECT_EQ(m0[15], 1.0);
  // Elsewhere: M (e, n, u, 1) equals the ECEF of fromEnu(e, n, u), to a millimetre.
  const io::GeoPosition origin{46.8426566, -91.9940080, 198.55};
  const auto m = geo::enuToEcefMatrix(origin);
  for (const std::array<double, 3> enu : {std::array<double, 3>{0, 0, 0}, {120.5, -80.25, 31.0},
                                          {-950.0, 1200.0, -40.0}}) {
    const auto want = geo::ecefOf(geo::fromEnu(enu, origin));
    for (int r = 0; r < 3; ++r) {
      const double got = m[r] * enu[0] + m[4 + r] * enu[1] + m[8 + r] * enu[2] + m[12 + r];
      EXPECT_NEAR(got, want[r], 1e-3) << "row " << r;
    }
  }
}

TEST(Geodesy, UtmZoneEpsgCodes) {
  EXPECT_EQ(geo::utmEpsg({46.843, -91.994, 0}), 32615);  // Duluth, MN: zone 15 N
  EXPECT_EQ(geo::utmEpsg({48.137, 11.575, 0}), 32632);   // Munich: zone 32 N
  EXPECT_EQ(geo::utmEpsg({-33.87, 151.21, 0}), 32756);   // Sydney: zone 56 S
  EXPECT_EQ(geo::utmEpsg({0.0, -180.0, 0}), 32601);
  EXPECT_EQ(geo::utmEpsg({0.0, 180.0, 0}), 32660);
}

TEST(Geodesy, SimilarityFitRecoversScaleRotationAndTranslationDespiteOutliers) {
  io::Similarity truth;
  truth.scale = 37.5;
  const double a = 0.7, c = std::cos(a), s = std::sin(a);
  // A rotation about z, then a tilt about x (an SfM frame is arbitrary).
  const double t = 0.3, ct = std::cos(t), st = std::sin(t);
  truth.rotation = {c, -s * ct, s * st, s, c * ct, -c * st, 0, st, ct};
  truth.translation = {100, -50, 20};
  std::mt19937 rng(3);
  std::normal_distribution<double> noise(0, 0.5);  // GPS noise, metres
  std::uniform_real_distribution<double> where(-2, 2);
  std::vector<std::array<double, 3>> from, to;
  for (int i = 0; i < 30; ++i) {
    const std::array<double, 3> x{where(rng), where(rng), 0.1 * where(rng)};
    auto y = truth.apply(x);
    for (auto& v : y) v += noise(rng);
    if (i % 10 == 3) y[2] += 80;  // three photos with a wild GPS altitude
    from.push_back(x);
    to.push_back(y);
  }
  std::vector<bool> inliers;
  bool consensus = false;
  const io::Similarity fit = geo::fitSimilarity(from, to, 3.0, &inliers, &consensus);
  EXPECT_TRUE(consensus);
  EXPECT_NEAR(fit.scale, truth.scale, 0.02 * truth.scale);
  for (int k = 0; k < 9; ++k) EXPECT_NEAR(fit.rotation[k], truth.rotation[k], 0.02) << k;
  for (int k = 0; k < 3; ++k) EXPECT_NEAR(fit.translation[k], truth.translation[k], 1.0) << k;
  int outliers_found = 0;
  for (int i = 0; i < 30; ++i) outliers_found += (i % 10 == 3) && !inliers[i];
  EXPECT_EQ(outliers_found, 3);
  EXPECT_EQ(std::count(inliers.begin(), inliers.end(), true), 27);
  // Too few or degenerate pairs are errors, not a NaN transform.
  EXPECT_THROW(geo::fitSimilarity({from[0], from[1]}, {to[0], to[1]}, 3.0), Error);
  EXPECT_THROW(geo::fitSimilarity({{0, 0, 0}, {1, 0, 0}, {2, 0, 0}, {3, 0, 0}},
                                  {{0, 0, 0}, {2, 0, 0}, {4, 0, 0}, {6, 0, 0}}, 3.0),
               Error);
}

// A reconstruction that does not match the flight (seen on a real 6-photo survey: two strips
// joined wrongly, camera centres 20-110 m from their GPS): no 3 pairs agree within the distance.
// The fit of all pairs comes back flagged, and only pairs really within the distance under it
// count as inliers (they were all reported as inliers before).
TEST(Geodesy, WithoutConsensusTheFitOfAllIsFlaggedAndInliersAreHonest) {
  std::mt19937 rng(7);
  std::normal_distribution<double> noise(0, 40);  // metres: a reconstruction that is wrong
  std::vector<std::array<double, 3>> from, to;
  for (int i = 0; i < 6; ++i) {
    const std::array<double, 3> x{10.0 * (i % 3), 20.0 * (i / 3), 0.0};
    from.push_back(x);
    to.push_back({x[0] + noise(rng), x[1] + noise(rng), x[2] + noise(rng)});
  }
  std::vector<bool> inliers;
  bool consensus = true;
  const io::Similarity fit = geo::fitSimilarity(from, to, 1.0, &inliers, &consensus);
  EXPECT_FALSE(consensus);
  int within = 0;
  for (int i = 0; i < 6; ++i) {
    const auto y = fit.apply(from[i]);
    const double d = std::hypot(y[0] - to[i][0], y[1] - to[i][1], y[2] - to[i][2]);
    EXPECT_EQ(static_cast<bool>(inliers[i]), d <= 1.0) << i << ": " << d << " m";
    within += d <= 1.0;
  }
  EXPECT_LT(within, 3);
  for (double v : fit.rotation) EXPECT_TRUE(std::isfinite(v));
}

}  // namespace
}  // namespace sadsplat
