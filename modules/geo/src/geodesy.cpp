#include "sadsplat/geo/geodesy.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <random>

#include "sadsplat/common/error.h"

namespace sadsplat {
namespace geo {
namespace {

using io::GeoPosition;
using io::Similarity;

constexpr double kPiWgs84 = 3.14159265358979323846;
constexpr double kA = 6378137.0;            // WGS84 semi-major axis
constexpr double kF = 1.0 / 298.257223563;  // WGS84 flattening
constexpr double kE2 = kF * (2 - kF);       // first eccentricity squared

double wgs84Radians(double deg) { return deg * kPiWgs84 / 180.0; }
double wgs84Degrees(double rad) { return rad * 180.0 / kPiWgs84; }

Eigen::Vector3d toEcef(const GeoPosition& p) {
  const double lat = wgs84Radians(p.latitude), lon = wgs84Radians(p.longitude);
  const double n = kA / std::sqrt(1 - kE2 * std::sin(lat) * std::sin(lat));
  return {(n + p.altitude) * std::cos(lat) * std::cos(lon),
          (n + p.altitude) * std::cos(lat) * std::sin(lon),
          (n * (1 - kE2) + p.altitude) * std::sin(lat)};
}

GeoPosition fromEcef(const Eigen::Vector3d& x) {
  // Bowring's iteration to convergence (sub-millimetre after a few steps).
  const double lon = std::atan2(x.y(), x.x());
  const double r = std::hypot(x.x(), x.y());
  double lat = std::atan2(x.z(), r * (1 - kE2)), alt = 0;
  for (int k = 0; k < 10; ++k) {
    const double n = kA / std::sqrt(1 - kE2 * std::sin(lat) * std::sin(lat));
    alt = r / std::cos(lat) - n;
    lat = std::atan2(x.z(), r * (1 - kE2 * n / (n + alt)));
  }
  return {wgs84Degrees(lat), wgs84Degrees(lon), alt};
}

// Rows: east, north, up at `origin`, in ECEF.
Eigen::Matrix3d enuBasis(const GeoPosition& origin) {
  const double lat = wgs84Radians(origin.latitude), lon = wgs84Radians(origin.longitude);
  Eigen::Matrix3d m;
  m << -std::sin(lon), std::cos(lon), 0,                                              //
      -std::sin(lat) * std::cos(lon), -std::sin(lat) * std::sin(lon), std::cos(lat),  //
      std::cos(lat) * std::cos(lon), std::cos(lat) * std::sin(lon), std::sin(lat);
  return m;
}

// Umeyama's least-squares similarity of the pairs in `idx`.
bool umeyama(const std::vector<std::array<double, 3>>& from,
             const std::vector<std::array<double, 3>>& to, const std::vector<int>& idx,
             Similarity* out) {
  const int n = static_cast<int>(idx.size());
  Eigen::Vector3d mf = Eigen::Vector3d::Zero(), mt = Eigen::Vector3d::Zero();
  for (int i : idx) {
    mf += Eigen::Vector3d(from[i].data());
    mt += Eigen::Vector3d(to[i].data());
  }
  mf /= n;
  mt /= n;
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  double var_from = 0;
  for (int i : idx) {
    const Eigen::Vector3d a = Eigen::Vector3d(from[i].data()) - mf;
    const Eigen::Vector3d b = Eigen::Vector3d(to[i].data()) - mt;
    cov += b * a.transpose();
    var_from += a.squaredNorm();
  }
  cov /= n;
  var_from /= n;
  if (!(var_from > 1e-18)) return false;
  Eigen::JacobiSVD<Eigen::Matrix3d> svd(cov, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d s = Eigen::Matrix3d::Identity();
  if (svd.matrixU().determinant() * svd.matrixV().determinant() < 0) s(2, 2) = -1;
  const Eigen::Vector3d sv = svd.singularValues();
  // Points on one line: the second singular value vanishes and the rotation about it is free.
  if (!(sv(1) > 1e-9 * std::max(1.0, sv(0)))) return false;
  const Eigen::Matrix3d R = svd.matrixU() * s * svd.matrixV().transpose();
  const double scale = (sv.asDiagonal() * s).trace() / var_from;
  const Eigen::Vector3d t = mt - scale * R * mf;
  for (int r = 0; r < 3; ++r) {
    for (int c = 0; c < 3; ++c) out->rotation[3 * r + c] = R(r, c);
    out->translation[r] = t(r);
  }
  out->scale = scale;
  return std::isfinite(scale) && scale > 0;
}

double distance(const Similarity& s, const std::array<double, 3>& a,
                const std::array<double, 3>& b) {
  const auto x = s.apply(a);
  return std::sqrt((x[0] - b[0]) * (x[0] - b[0]) + (x[1] - b[1]) * (x[1] - b[1]) +
                   (x[2] - b[2]) * (x[2] - b[2]));
}

}  // namespace

std::array<double, 3> toEnu(const GeoPosition& p, const GeoPosition& origin) {
  const Eigen::Vector3d d = enuBasis(origin) * (toEcef(p) - toEcef(origin));
  return {d.x(), d.y(), d.z()};
}

GeoPosition fromEnu(const std::array<double, 3>& enu, const GeoPosition& origin) {
  const Eigen::Vector3d x =
      toEcef(origin) + enuBasis(origin).transpose() * Eigen::Vector3d(enu[0], enu[1], enu[2]);
  return fromEcef(x);
}

std::array<double, 3> ecefOf(const GeoPosition& p) {
  const Eigen::Vector3d x = toEcef(p);
  return {x.x(), x.y(), x.z()};
}

std::array<double, 16> enuToEcefMatrix(const GeoPosition& origin) {
  const Eigen::Matrix3d rows = enuBasis(origin);  // rows: east, north, up
  const Eigen::Vector3d o = toEcef(origin);
  std::array<double, 16> m{};
  for (int c = 0; c < 3; ++c) {
    for (int r = 0; r < 3; ++r) m[4 * c + r] = rows(c, r);
  }
  for (int r = 0; r < 3; ++r) m[12 + r] = o[r];
  m[15] = 1;
  return m;
}

Similarity fitSimilarity(const std::vector<std::array<double, 3>>& from,
                         const std::vector<std::array<double, 3>>& to, double inlier_metres,
                         std::vector<bool>* inliers, bool* consensus) {
  const int n = static_cast<int>(from.size());
  if (n < 3 || to.size() != from.size()) {
    throw Error("<georeference>", "position pairs", "at least 3 (camera centre, GPS) pairs",
                std::to_string(std::min(from.size(), to.size())));
  }
  std::vector<int> best;
  std::mt19937 rng(12345);  // deterministic
  std::vector<int> all(n);
  for (int i = 0; i < n; ++i) all[i] = i;
  const int trials = n <= 8 ? 200 : 1000;
  for (int trial = 0; trial < trials; ++trial) {
    std::vector<int> sample = all;
    std::shuffle(sample.begin(), sample.end(), rng);
    sample.resize(3);
    Similarity s;
    if (!umeyama(from, to, sample, &s)) continue;
    std::vector<int> in;
    for (int i = 0; i < n; ++i) {
      if (distance(s, from[i], to[i]) <= inlier_metres) in.push_back(i);
    }
    if (in.size() > best.size()) best = in;
    if (static_cast<int>(best.size()) == n) break;
  }
  Similarity s;
  const bool agreed = best.size() >= 3 && umeyama(from, to, best, &s);
  if (!agreed && !umeyama(from, to, all, &s)) {
    // No consensus within the distance (GPS noisier than assumed, or a reconstruction that does
    // not match the flight): the least-squares fit of all, reported as such.
    throw Error("<georeference>", "camera centres",
                "positions not all on one line (a flight with some extent across)",
                "degenerate positions");
  }
  if (inliers != nullptr) {
    inliers->assign(n, false);
    for (int i = 0; i < n; ++i) (*inliers)[i] = distance(s, from[i], to[i]) <= inlier_metres;
  }
  if (consensus != nullptr) *consensus = agreed;
  return s;
}

}  // namespace geo
}  // namespace sadsplat
