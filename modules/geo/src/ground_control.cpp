#include "sadsplat/geo/ground_control.h"
#include "sadsplat/geo/geodesy.h"

#include <Eigen/Dense>

#include <algorithm>
#include <cctype>
#include <cmath>
#include <cstdlib>
#include <fstream>
#include <map>
#include <set>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/filesystem.h"

namespace sadsplat {
namespace geo {
namespace {

std::string lineField(int line, const std::string& field) {
  return "line " + std::to_string(line) + " " + field;
}

double parseNumber(const std::string& path, int line, const char* field, const std::string& s) {
  char* end = nullptr;
  const double v = std::strtod(s.c_str(), &end);
  if (s.empty() || end != s.c_str() + s.size() || !std::isfinite(v)) {
    throw Error(path, lineField(line, field), "a finite number", s);
  }
  return v;
}

bool markedCheck(const std::string& name) {
  std::string lower;
  for (char c : name)
    lower.push_back(static_cast<char>(std::tolower(static_cast<unsigned char>(c))));
  return lower.rfind("chk", 0) == 0 || lower.rfind("check", 0) == 0;
}

// Normalised camera coordinates (u, v) -> distorted ones, for the models triangulation takes.
Eigen::Vector2d distort(const io::ColmapCamera& c, const Eigen::Vector2d& p) {
  const auto& k = c.params;
  const double r2 = p.squaredNorm();
  switch (c.model) {
    case io::CameraModel::kSimplePinhole:
    case io::CameraModel::kPinhole:
      return p;
    case io::CameraModel::kSimpleRadial:
      return p * (1 + k[3] * r2);
    case io::CameraModel::kRadial:
      return p * (1 + k[3] * r2 + k[4] * r2 * r2);
    case io::CameraModel::kOpenCV: {
      const double u = p.x(), v = p.y(), radial = 1 + k[4] * r2 + k[5] * r2 * r2;
      return {u * radial + 2 * k[6] * u * v + k[7] * (r2 + 2 * u * u),
              v * radial + k[6] * (r2 + 2 * v * v) + 2 * k[7] * u * v};
    }
    default:
      return p;
  }
}

struct Intrinsics {
  double fx, fy, cx, cy;
};

Intrinsics intrinsicsOf(const io::ColmapCamera& c) {
  const auto& k = c.params;
  if (io::cameraModelHasFy(c.model)) return {k[0], k[1], k[2], k[3]};
  return {k[0], k[0], k[1], k[2]};
}

bool supported(io::CameraModel m) {
  return m == io::CameraModel::kSimplePinhole || m == io::CameraModel::kPinhole ||
         m == io::CameraModel::kSimpleRadial || m == io::CameraModel::kRadial ||
         m == io::CameraModel::kOpenCV;
}

// Pixel -> normalised undistorted coordinates: COLMAP's fixed-point iteration.
Eigen::Vector2d undistortPixel(const io::ColmapCamera& c, double px, double py) {
  const Intrinsics in = intrinsicsOf(c);
  const Eigen::Vector2d d((px - in.cx) / in.fx, (py - in.cy) / in.fy);
  Eigen::Vector2d u = d;
  for (int it = 0; it < 100; ++it) {
    const Eigen::Vector2d next = u + (d - distort(c, u));
    if ((next - u).norm() < 1e-12) return next;
    u = next;
  }
  return u;
}

Eigen::Matrix3d rotationOf(const std::array<double, 4>& q) {
  return Eigen::Quaterniond(q[0], q[1], q[2], q[3]).normalized().toRotationMatrix();
}

}  // namespace

GcpList readGcpList(const std::string& path, const std::vector<std::string>& photos) {
  io::requireRegularFile(path);
  std::ifstream in(path);
  if (!in) throw Error(path, "file", "a readable gcp_list.txt", "cannot open");
  GcpList list;
  list.path = path;
  std::string text;
  int line = 0;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    const auto first = text.find_first_not_of(" \t");
    if (first == std::string::npos || text[first] == '#') continue;
    list.crs = text.substr(first, text.find_last_not_of(" \t") - first + 1);
    break;
  }
  if (list.crs.empty())
    throw Error(path, "CRS (first line)", "a CRS line, then observations", "an empty file");
  const std::set<std::string> known(photos.begin(), photos.end());
  std::map<std::string, GroundControlPoint> by_key;
  while (std::getline(in, text)) {
    ++line;
    if (!text.empty() && text.back() == '\r') text.pop_back();
    std::istringstream fields(text);
    std::vector<std::string> f;
    for (std::string s; fields >> s;) f.push_back(s);
    if (f.empty() || f[0][0] == '#') continue;
    if (f.size() < 6) {
      throw Error(path, lineField(line, "fields"), "x y z px py image [name]",
                  std::to_string(f.size()) + " fields");
    }
    const std::array<double, 3> xyz{parseNumber(path, line, "x", f[0]),
                                    parseNumber(path, line, "y", f[1]),
                                    parseNumber(path, line, "z", f[2])};
    GcpObservation o;
    o.px = parseNumber(path, line, "px", f[3]);
    o.py = parseNumber(path, line, "py", f[4]);
    o.image = f[5];
    o.line = line;
    if (o.px < 0 || o.py < 0) {
      throw Error(path, lineField(line, "px py"), "pixel coordinates >= 0", f[3] + " " + f[4]);
    }
    if (!known.empty() && !known.count(o.image)) {
      throw Error(path, lineField(line, "image"), "a photo of the photo folder", o.image);
    }
    std::ostringstream key;
    key.precision(17);
    if (f.size() >= 7) {
      key << "name:" << f[6];
    } else {
      key << "xyz:" << xyz[0] << " " << xyz[1] << " " << xyz[2];
    }
    auto [it, added] = by_key.try_emplace(key.str());
    GroundControlPoint& p = it->second;
    if (added) {
      p.name = f.size() >= 7 ? f[6] : "gcp_line_" + std::to_string(line);
      p.crs_xyz = xyz;
      p.check = markedCheck(p.name);
    } else if (p.crs_xyz != xyz) {
      throw Error(path, lineField(line, "x y z"),
                  "the coordinates of the earlier lines of point " + p.name,
                  f[0] + " " + f[1] + " " + f[2]);
    }
    for (const auto& earlier : p.observations) {
      if (earlier.image == o.image) {
        throw Error(path, lineField(line, "image"),
                    "one mark of point " + p.name + " per photo (line " +
                        std::to_string(earlier.line) + " marks it there already)",
                    o.image);
      }
    }
    p.observations.push_back(o);
  }
  for (auto& [key, p] : by_key) list.points.push_back(std::move(p));
  std::sort(
      list.points.begin(), list.points.end(),
      [](const GroundControlPoint& a, const GroundControlPoint& b) { return a.name < b.name; });
  for (const auto& p : list.points) {
    if (p.observations.size() < 2) {
      throw Error(path,
                  "point " + p.name + " (line " + std::to_string(p.observations[0].line) + ")",
                  "marks on at least 2 photos (a point seen once cannot be triangulated)",
                  std::to_string(p.observations.size()));
    }
  }
  const bool any_marked = std::any_of(list.points.begin(), list.points.end(),
                                      [](const GroundControlPoint& p) { return p.check; });
  if (!any_marked && list.points.size() >= 5) {
    for (std::size_t i = 3; i < list.points.size(); i += 4) list.points[i].check = true;
  }
  const auto controls = std::count_if(list.points.begin(), list.points.end(),
                                      [](const GroundControlPoint& p) { return !p.check; });
  if (controls < 3) {
    throw Error(path, "points", "at least 3 control points (not counting check points)",
                std::to_string(controls));
  }
  std::vector<std::array<double, 3>> xyz;
  for (const auto& p : list.points) xyz.push_back(p.crs_xyz);
  const std::vector<io::GeoPosition> wgs84 = crsToWgs84(list.crs, xyz, path);
  for (std::size_t i = 0; i < list.points.size(); ++i) list.points[i].wgs84 = wgs84[i];
  return list;
}

TriangulatedGcp triangulateGcp(const io::ColmapModel& model, const GroundControlPoint& point) {
  TriangulatedGcp t;
  std::map<std::string, const io::ColmapImage*> images;
  for (const auto& im : model.images) images[im.name] = &im;
  std::map<std::uint32_t, const io::ColmapCamera*> cameras;
  for (const auto& c : model.cameras) cameras[c.id] = &c;
  struct Ray {
    Eigen::Vector3d centre, direction;
    const io::ColmapImage* image;
    const io::ColmapCamera* camera;
    double px, py;
  };
  std::vector<Ray> rays;
  for (const auto& o : point.observations) {
    const auto im = images.find(o.image);
    if (im == images.end()) continue;  // not registered
    const auto cam = cameras.find(im->second->camera_id);
    if (cam == cameras.end()) continue;
    if (!supported(cam->second->model)) {
      t.why = std::string("camera model ") + io::cameraModelName(cam->second->model) +
              " of photo " + o.image + " (triangulation takes pinhole and radial models)";
      return t;
    }
    const Eigen::Matrix3d R = rotationOf(im->second->qvec);
    const Eigen::Vector3d tv(im->second->tvec[0], im->second->tvec[1], im->second->tvec[2]);
    const Eigen::Vector2d u = undistortPixel(*cam->second, o.px, o.py);
    rays.push_back({-R.transpose() * tv,
                    (R.transpose() * Eigen::Vector3d(u.x(), u.y(), 1)).normalized(), im->second,
                    cam->second, o.px, o.py});
  }
  t.marks = static_cast<int>(rays.size());
  if (rays.size() < 2) {
    t.why = std::to_string(rays.size()) + " of its marks on registered photos (2 needed)";
    return t;
  }
  Eigen::Matrix3d A = Eigen::Matrix3d::Zero();
  Eigen::Vector3d b = Eigen::Vector3d::Zero();
  for (const auto& r : rays) {
    const Eigen::Matrix3d P = Eigen::Matrix3d::Identity() - r.direction * r.direction.transpose();
    A += P;
    b += P * r.centre;
  }
  Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d> eig(A);
  if (!(eig.eigenvalues()(0) > 1e-8 * eig.eigenvalues()(2))) {
    t.why = "its rays are parallel (marks on photos taken from one place)";
    return t;
  }
  const Eigen::Vector3d X = A.ldlt().solve(b);
  double sq = 0;
  for (const auto& r : rays) {
    const Eigen::Matrix3d R = rotationOf(r.image->qvec);
    const Eigen::Vector3d c =
        R * X + Eigen::Vector3d(r.image->tvec[0], r.image->tvec[1], r.image->tvec[2]);
    if (!(c.z() > 0)) {
      t.why = "it lands behind photo " + r.image->name;
      return t;
    }
    const Eigen::Vector2d d = distort(*r.camera, Eigen::Vector2d(c.x() / c.z(), c.y() / c.z()));
    const Intrinsics in = intrinsicsOf(*r.camera);
    sq += std::pow(in.fx * d.x() + in.cx - r.px, 2) + std::pow(in.fy * d.y() + in.cy - r.py, 2);
  }
  t.reprojection_px = std::sqrt(sq / rays.size());
  t.sfm = {X.x(), X.y(), X.z()};
  t.ok = true;
  return t;
}

GcpFit fitGcpGeoreference(const io::ColmapModel& model, const GcpList& gcps,
                          const io::GeoPosition& origin) {
  GcpFit fit;
  std::vector<std::array<double, 3>> from, to;
  struct Placed {
    const GroundControlPoint* point;
    TriangulatedGcp t;
    std::array<double, 3> enu;
  };
  std::vector<Placed> placed;
  for (const auto& p : gcps.points) {
    TriangulatedGcp t = triangulateGcp(model, p);
    if (!t.ok) {
      fit.skipped.push_back(p.name + ": " + t.why);
      continue;
    }
    placed.push_back({&p, t, geo::toEnu(p.wgs84, origin)});
    if (!p.check) from.push_back(t.sfm), to.push_back(placed.back().enu);
  }
  if (from.size() < 3) {
    throw Error(gcps.path, "control points", "at least 3 triangulated in the reconstruction",
                std::to_string(from.size()) +
                    (fit.skipped.empty() ? "" : " (" + fit.skipped.front() + ")"));
  }
  io::Georeference& g = fit.georeference;
  g.origin = origin;
  g.epsg_utm = geo::utmEpsg(origin);
  g.up_source = "ground control points";
  // Least squares over every control point: surveyed points are trusted, their residuals shown.
  bool consensus = false;
  g.sfm_to_local = geo::fitSimilarity(from, to, 1e12, nullptr, &consensus);
  double ch2 = 0, cv2 = 0, kh2 = 0, kv2 = 0;
  for (const auto& p : placed) {
    const auto x = g.sfm_to_local.apply(p.t.sfm);
    GcpResidual r;
    r.name = p.point->name;
    r.check = p.point->check;
    r.horizontal = std::hypot(x[0] - p.enu[0], x[1] - p.enu[1]);
    r.vertical = x[2] - p.enu[2];
    r.reprojection_px = p.t.reprojection_px;
    r.marks = p.t.marks;
    fit.residuals.push_back(r);
    if (r.check) {
      kh2 += r.horizontal * r.horizontal, kv2 += r.vertical * r.vertical, ++g.check_points;
    } else {
      ch2 += r.horizontal * r.horizontal, cv2 += r.vertical * r.vertical, ++g.control_points;
    }
  }
  g.horizontal_rms_metres = std::sqrt(ch2 / g.control_points);
  g.vertical_rms_metres = std::sqrt(cv2 / g.control_points);
  g.rms_metres = std::sqrt((ch2 + cv2) / g.control_points);
  g.inliers = g.control_points;
  g.consensus = true;
  if (g.check_points > 0) {
    g.check_rmse_horizontal = std::sqrt(kh2 / g.check_points);
    g.check_rmse_vertical = std::sqrt(kv2 / g.check_points);
  }
  return fit;
}

}  // namespace geo
}  // namespace sadsplat
