#include "sadsplat/geo/gps_georeference.h"
#include "sadsplat/geo/geodesy.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cmath>
#include <complex>
#include <numeric>
#include <random>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/common/order_statistics.h"

namespace sadsplat {
namespace geo {
namespace {

constexpr double kPi = 3.14159265358979323846;
// The median of a 2D normal's radius is sigma * sqrt(2 ln 2) (a Rayleigh distribution).
constexpr double kRayleighMedian = 1.1774100225154747;
// The 2D radius that 99.73 % of a 2D normal's draws stay within (as 3 sigma in 1D):
// sigma * sqrt(-2 ln 0.0027).
constexpr double kInlierSigmas = 3.4393;

Eigen::Vector3d vec(const std::array<double, 3>& a) { return {a[0], a[1], a[2]}; }
std::array<double, 3> arr(const Eigen::Vector3d& v) { return {v.x(), v.y(), v.z()}; }

// The upper median of a copy (0 for none).
double median(std::vector<double> v) { return quantileInPlace(v, 0.5); }

using Complex = std::complex<double>;

// The plane similarity g = a w + b (a = scale * e^{i heading}) of the pairs in `idx`, least
// squares.
bool fitPlaneSimilarity(const std::vector<Complex>& w, const std::vector<Complex>& g,
                        const std::vector<int>& idx, Complex* a, Complex* b) {
  if (idx.size() < 2) return false;
  Complex mw = 0, mg = 0;
  for (int i : idx) mw += w[i], mg += g[i];
  mw /= static_cast<double>(idx.size());
  mg /= static_cast<double>(idx.size());
  Complex num = 0;
  double den = 0;
  for (int i : idx) {
    num += std::conj(w[i] - mw) * (g[i] - mg);
    den += std::norm(w[i] - mw);
  }
  if (!(den > 1e-18)) return false;
  *a = num / den;
  *b = mg - *a * mw;
  return std::abs(*a) > 0 && std::isfinite(std::abs(*a));
}

std::string twoDecimals(double d) {
  std::ostringstream s;
  s.precision(2);
  s << std::fixed << d;
  return s.str();
}

}  // namespace

double angleDegrees(const std::array<double, 3>& a, const std::array<double, 3>& b) {
  const double c = vec(a).normalized().dot(vec(b).normalized());
  return std::acos(std::clamp(c, -1.0, 1.0)) * 180.0 / kPi;
}

UpCue upFromViews(const std::vector<std::array<double, 3>>& viewing) {
  UpCue cue;
  if (viewing.empty()) return cue;
  Eigen::Vector3d sum = Eigen::Vector3d::Zero();
  for (const auto& v : viewing) sum += vec(v).normalized();
  cue.quality = sum.norm() / viewing.size();
  if (!(sum.norm() > 0)) return cue;
  cue.up = arr(-sum.normalized());
  cue.found = cue.quality >= std::cos(20.0 * kPi / 180.0);
  return cue;
}

UpCue upFromGround(const std::vector<std::array<double, 3>>& all_points,
                   const std::array<double, 3>& camera_mean) {
  UpCue cue;
  if (all_points.size() < 20) return cue;
  // At most 20000 points, evenly strided (deterministic).
  std::vector<Eigen::Vector3d> p;
  const std::size_t stride = std::max<std::size_t>(1, all_points.size() / 20000);
  for (std::size_t i = 0; i < all_points.size(); i += stride) p.push_back(vec(all_points[i]));
  const int n = static_cast<int>(p.size());
  // The spread: the median distance to the coordinate-wise median.
  Eigen::Vector3d centre;
  for (int k = 0; k < 3; ++k) {
    std::vector<double> c(n);
    for (int i = 0; i < n; ++i) c[i] = p[i](k);
    centre(k) = median(c);
  }
  std::vector<double> d(n);
  for (int i = 0; i < n; ++i) d[i] = (p[i] - centre).norm();
  const double spread = median(d);
  if (!(spread > 0)) return cue;
  const double tolerance = 0.01 * spread;
  std::mt19937 rng(20261128);
  std::uniform_int_distribution<int> pick(0, n - 1);
  int best_count = -1;
  Eigen::Vector3d best_normal(0, 0, 1), best_point = centre;
  const int probe = std::min(n, 2000);  // the trials count on an evenly strided subset
  for (int trial = 0; trial < 400; ++trial) {
    const Eigen::Vector3d a = p[pick(rng)], b = p[pick(rng)], c = p[pick(rng)];
    Eigen::Vector3d normal = (b - a).cross(c - a);
    if (!(normal.norm() > 1e-12 * spread * spread)) continue;
    normal.normalize();
    int count = 0;
    for (int k = 0; k < probe; ++k) {
      if (std::abs(normal.dot(p[static_cast<std::size_t>(k) * n / probe] - a)) <= tolerance)
        ++count;
    }
    if (count > best_count) best_count = count, best_normal = normal, best_point = a;
  }
  // Least squares on the plane's points: the smallest principal axis.
  std::vector<int> in;
  for (int i = 0; i < n; ++i) {
    if (std::abs(best_normal.dot(p[i] - best_point)) <= tolerance) in.push_back(i);
  }
  if (in.size() < 3) return cue;
  Eigen::Vector3d mean = Eigen::Vector3d::Zero();
  for (int i : in) mean += p[i];
  mean /= static_cast<double>(in.size());
  Eigen::Matrix3d cov = Eigen::Matrix3d::Zero();
  for (int i : in) cov += (p[i] - mean) * (p[i] - mean).transpose();
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(cov);
  Eigen::Vector3d normal = eig.eigenvectors().col(0).normalized();
  if (normal.dot(vec(camera_mean) - mean) < 0) normal = -normal;
  cue.up = arr(normal);
  cue.quality = static_cast<double>(in.size()) / n;
  cue.found = cue.quality >= 0.15;
  return cue;
}

GpsFit fitGpsGeoreference(const std::vector<GpsPhoto>& photos,
                          const std::vector<std::array<double, 3>>& points,
                          const io::GeoPosition& origin, const GpsFitOptions& options) {
  std::vector<const GpsPhoto*> with_gps;
  std::vector<std::array<double, 3>> viewing;
  Eigen::Vector3d camera_mean = Eigen::Vector3d::Zero();
  for (const auto& p : photos) {
    if (p.gps) with_gps.push_back(&p);
    viewing.push_back(p.viewing);
    camera_mean += vec(p.centre) / static_cast<double>(photos.size());
  }
  const int n = static_cast<int>(with_gps.size());
  if (n < 3) {
    throw Error("<georeference>", "photos with GPS", "at least 3 registered photos with GPS",
                std::to_string(n));
  }
  // The GPS accuracy the fit starts from: the user's, else the photos' own (median), else a
  // default.
  std::vector<double> stated;
  for (const auto* p : with_gps) {
    if (p->stated_accuracy > 0) stated.push_back(p->stated_accuracy);
  }
  const double accuracy = options.accuracy > 0                   ? options.accuracy
                          : stated.size() * 2 >= with_gps.size() ? median(stated)
                                                                 : kDefaultGpsAccuracy;
  const bool accuracy_stated = options.accuracy > 0 || stated.size() * 2 >= with_gps.size();

  GpsFit fit;
  io::Georeference& g = fit.georeference;
  g.origin = origin;
  g.epsg_utm = geo::utmEpsg(origin);
  g.photos_with_gps = n;
  g.gps_accuracy_metres = accuracy;

  const UpCue views = upFromViews(viewing);
  const UpCue ground = upFromGround(points, arr(camera_mean));
  std::vector<std::string>& doubts = g.doubts;

  std::vector<std::array<double, 3>> centres, targets;
  for (const auto* p : with_gps) centres.push_back(p->centre), targets.push_back(*p->gps);

  std::vector<bool> inlier(n, false);
  if (views.found || ground.found) {
    const UpCue& up = views.found ? views : ground;
    g.up_source = views.found ? "nadir views" : "ground plane";
    const Eigen::Matrix3d level =
        Eigen::Quaterniond::FromTwoVectors(vec(up.up), Eigen::Vector3d::UnitZ()).toRotationMatrix();
    std::vector<Complex> w(n), t(n);
    for (int i = 0; i < n; ++i) {
      const Eigen::Vector3d c = level * vec(centres[i]);
      w[i] = {c.x(), c.y()};
      t[i] = {targets[i][0], targets[i][1]};
    }
    // RANSAC over pairs (two pairs fix a plane similarity), inliers within the 2D 3 sigma.
    const double first_threshold = kInlierSigmas * accuracy;
    std::vector<int> best;
    const auto inliersOf = [&](Complex a, Complex b, double threshold) {
      std::vector<int> in;
      for (int i = 0; i < n; ++i) {
        if (std::abs(a * w[i] + b - t[i]) <= threshold) in.push_back(i);
      }
      return in;
    };
    std::mt19937 rng(12345);
    std::uniform_int_distribution<int> pick(0, n - 1);
    const bool every_pair = n <= 64;
    const int trials = every_pair ? n * (n - 1) / 2 : 2000;
    for (int trial = 0, i = 0, j = 1; trial < trials; ++trial) {
      int a_index = i, b_index = j;
      if (every_pair) {
        if (++j == n) ++i, j = i + 1;
      } else {
        a_index = pick(rng), b_index = pick(rng);
      }
      if (a_index == b_index || std::abs(w[a_index] - w[b_index]) < 1e-12) continue;
      const Complex a = (t[b_index] - t[a_index]) / (w[b_index] - w[a_index]);
      const Complex b = t[a_index] - a * w[a_index];
      const std::vector<int> in = inliersOf(a, b, first_threshold);
      if (in.size() > best.size()) best = in;
    }
    Complex a, b;
    std::vector<int> all(n);
    std::iota(all.begin(), all.end(), 0);
    if (best.size() < 3) {
      doubts.push_back("no 3 photos' GPS agree with the reconstruction within " +
                       twoDecimals(first_threshold) + " m: the fit of all");
      best = all;
    }
    if (!fitPlaneSimilarity(w, t, best, &a, &b)) {
      throw Error("<georeference>", "camera centres", "photos spread over some area",
                  "all at one point");
    }
    // The threshold from the data: the 2D 3 sigma of the noise measured on the agreeing photos,
    // a few rounds.
    double noise = accuracy, threshold = first_threshold;
    for (int round = 0; round < 5 && best.size() >= 3; ++round) {
      std::vector<double> r;
      for (int i : best) r.push_back(std::abs(a * w[i] + b - t[i]));
      noise = std::max(0.01, median(r) / kRayleighMedian);
      // Never tighter than the accuracy the fit started from: a photo within its stated 1 sigma
      // agrees.
      threshold = std::max(kInlierSigmas * noise, accuracy);
      std::vector<int> in = inliersOf(a, b, threshold);
      if (in.size() < 3) break;
      const bool same = in == best;
      best = in;
      if (!fitPlaneSimilarity(w, t, best, &a, &b)) break;
      if (same) break;
    }
    g.gps_noise_metres = noise;
    g.inlier_metres = threshold;
    // Altitude only as the median offset: camera GPS altitudes wander by tens of metres.
    const double scale = std::abs(a), heading = std::arg(a);
    const Eigen::Matrix3d turn =
        Eigen::AngleAxisd(heading, Eigen::Vector3d::UnitZ()).toRotationMatrix();
    const Eigen::Matrix3d rotation = turn * level;
    std::vector<double> offsets;
    for (int i : best) offsets.push_back(targets[i][2] - scale * (rotation * vec(centres[i])).z());
    const double dz = median(offsets);
    g.sfm_to_local.scale = scale;
    for (int r = 0; r < 3; ++r)
      for (int c = 0; c < 3; ++c) g.sfm_to_local.rotation[3 * r + c] = rotation(r, c);
    g.sfm_to_local.translation = {b.real(), b.imag(), dz};
    for (int i : best) inlier[i] = true;
    // How well the flight fixes the scale: the noise over the spread of the agreeing photos.
    Complex mean = 0;
    for (int i : best) mean += t[i];
    mean /= static_cast<double>(best.size());
    double spread2 = 0;
    for (int i : best) spread2 += std::norm(t[i] - mean);
    const double scale_uncertainty = noise / std::sqrt(std::max(spread2, 1e-18));
    g.scale_uncertainty = scale_uncertainty;
    if (scale_uncertainty > 0.02) {
      doubts.push_back("the flight is small against the GPS noise: its scale is uncertain by " +
                       twoDecimals(100 * scale_uncertainty) + " %");
    }
    if (accuracy_stated && noise > 2 * accuracy) {
      doubts.push_back("the GPS is noisier (" + twoDecimals(noise) + " m) than its stated " +
                       twoDecimals(accuracy) + " m");
    }
  } else {
    g.up_source = "gps 3D fit";
    doubts.push_back(
        "no up direction in the scene (the views are not nadir and the sparse points have no "
        "dominant plane): the tilt comes from the GPS altitudes");
    bool consensus = false;
    g.sfm_to_local =
        geo::fitSimilarity(centres, targets, kInlierSigmas * accuracy, &inlier, &consensus);
    g.inlier_metres = kInlierSigmas * accuracy;
    g.gps_noise_metres = accuracy;
    if (!consensus) doubts.push_back("no 3 photos' GPS agree with the reconstruction");
  }

  // Residuals and RMS over the agreeing photos.
  double h2 = 0, v2 = 0;
  int agreeing = 0;
  for (int i = 0; i < n; ++i) {
    const auto x = g.sfm_to_local.apply(centres[i]);
    GpsResidual r;
    r.photo = with_gps[i]->name;
    r.horizontal = std::hypot(x[0] - targets[i][0], x[1] - targets[i][1]);
    r.vertical = x[2] - targets[i][2];
    r.inlier = inlier[i];
    if (r.inlier) h2 += r.horizontal * r.horizontal, v2 += r.vertical * r.vertical, ++agreeing;
    fit.residuals.push_back(r);
  }
  g.inliers = agreeing;
  g.consensus = agreeing >= 3;
  g.horizontal_rms_metres = std::sqrt(h2 / std::max(1, agreeing));
  g.vertical_rms_metres = std::sqrt(v2 / std::max(1, agreeing));
  g.rms_metres = std::sqrt((h2 + v2) / std::max(1, agreeing));
  if (agreeing * 2 < n) {
    doubts.push_back("only " + std::to_string(agreeing) + " of " + std::to_string(n) +
                     " photos' GPS agree with the reconstruction");
  }

  // The sanity check in the fitted frame: how far the scene's own up cues are from z.
  Eigen::Matrix3d rotation;
  for (int r = 0; r < 3; ++r)
    for (int c = 0; c < 3; ++c) rotation(r, c) = g.sfm_to_local.rotation[3 * r + c];
  const std::array<double, 3> z{0, 0, 1};
  if (views.found) g.views_tilt_deg = angleDegrees(arr(rotation * vec(views.up)), z);
  if (ground.found) g.ground_tilt_deg = angleDegrees(arr(rotation * vec(ground.up)), z);
  if (views.found && ground.found && angleDegrees(views.up, ground.up) > 5) {
    doubts.push_back("the nadir views and the ground plane disagree by " +
                     twoDecimals(angleDegrees(views.up, ground.up)) +
                     " degrees (sloping ground, or a camera that was not level)");
  }
  return fit;
}

}  // namespace geo
}  // namespace sadsplat
