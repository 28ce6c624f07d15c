#include "sadsplat/geo/las_export.h"

#include <algorithm>
#include <cmath>
#include <map>
#include <sstream>

#include "sadsplat/common/error.h"
#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/las.h"
#include "sadsplat/io/run_directory.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace geo {
namespace {

using Vec3 = std::array<double, 3>;
constexpr double kShC0 = 0.28209479177387814;

std::uint16_t to16(double unit) {
  return static_cast<std::uint16_t>(std::lround(std::min(1.0, std::max(0.0, unit)) * 65535.0));
}

// Labels as ASPRS codes: class c -> codes[c]; none -> 1 (or 0 when there are no classes).
std::vector<int> codesFor(const LasExportOptions& o) {
  std::vector<std::string> names;
  for (const ClassInfo& c : o.classes) names.push_back(c.name);
  return io::asprsCodes(names, o.classification_map);
}

std::string finish(const std::string& path, std::vector<io::LasPoint>& points,
                   const std::vector<Vec3>& scene_xyz, const LasExportOptions& o) {
  io::LasHeader header;
  std::string crs;
  if (o.georeference) {
    const std::vector<Vec3> map = enuToUtm(*o.georeference, scene_xyz);
    for (std::size_t i = 0; i < points.size(); ++i) {
      points[i].x = map[i][0];
      points[i].y = map[i][1];
      points[i].z = map[i][2];
    }
    const Crs utm = crsOfEpsg(o.georeference->epsg_utm);
    header.wkt = utm.wkt;
    crs = utm.name;
  } else if (o.local_frame) {
    for (std::size_t i = 0; i < points.size(); ++i) {
      const Vec3 m = o.local_frame->toMap(scene_xyz[i]);
      points[i].x = m[0];
      points[i].y = m[1];
      points[i].z = m[2];
    }
    header.wkt = o.local_frame->wkt;
    crs = "local metres of the map (no georeference)";
  } else {
    for (std::size_t i = 0; i < points.size(); ++i) {
      points[i].x = scene_xyz[i][0];
      points[i].y = scene_xyz[i][1];
      points[i].z = scene_xyz[i][2];
    }
    header.wkt = localCrsWkt();
    crs = "local metres (no georeference)";
  }
  io::writeLas(path, points, header);
  std::map<int, std::size_t> histogram;
  for (const io::LasPoint& p : points) ++histogram[p.classification];
  std::ostringstream s;
  s << "wrote " << path << ": " << points.size() << " points, " << crs << "; classes:";
  const auto& names = io::asprsClassNames();
  for (const auto& [code, count] : histogram) {
    const auto it = names.find(code);
    s << " " << code << " (" << (it != names.end() ? it->second : "user") << ") " << count;
  }
  return s.str();
}

}  // namespace

std::string writeGaussiansLas(const std::string& path, const pcl::PointCloud<GaussianPoint>& cloud,
                              const LasExportOptions& o) {
  const std::vector<int> codes = codesFor(o);
  std::vector<io::LasPoint> points(cloud.size());
  std::vector<Vec3> xyz(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const GaussianPoint& g = cloud[i];
    xyz[i] = {g.x, g.y, g.z};
    for (int c = 0; c < 3; ++c) points[i].rgb[c] = to16(0.5 + kShC0 * g.f_dc[c]);
    points[i].classification = g.label < codes.size()
                                   ? static_cast<std::uint8_t>(codes[g.label])
                                   : static_cast<std::uint8_t>(o.classes.empty() ? 0 : 1);
  }
  return finish(path, points, xyz, o);
}

std::string writeSemanticLas(const std::string& path,
                             const pcl::PointCloud<pcl::PointXYZRGBL>& cloud,
                             const LasExportOptions& o) {
  const std::vector<int> codes = codesFor(o);
  std::vector<io::LasPoint> points(cloud.size());
  std::vector<Vec3> xyz(cloud.size());
  for (std::size_t i = 0; i < cloud.size(); ++i) {
    const pcl::PointXYZRGBL& p = cloud[i];
    xyz[i] = {p.x, p.y, p.z};
    points[i].rgb = {std::uint16_t(p.r * 257), std::uint16_t(p.g * 257), std::uint16_t(p.b * 257)};
    points[i].classification = p.label < codes.size()
                                   ? static_cast<std::uint8_t>(codes[p.label])
                                   : static_cast<std::uint8_t>(o.classes.empty() ? 0 : 1);
  }
  return finish(path, points, xyz, o);
}

std::string modelFolder(const std::string& model_path) {
  if (io::isDirectory(model_path)) return model_path;
  const std::size_t slash = model_path.find_last_of('/');
  return slash == std::string::npos ? "." : model_path.substr(0, slash);
}

LasExportOptions lasOptionsBeside(const std::string& model_path,
                                  const std::string& classification_map) {
  const std::string dir = modelFolder(model_path);
  LasExportOptions o;
  o.classification_map = classification_map;
  // A model's run directory (or any folder holding a model with these files beside it).
  const io::RunDirectory run(dir);
  if (io::optionalFileExists(run.classes())) o.classes = io::readClassesJson(run.classes());
  if (io::optionalFileExists(run.georeference())) {
    o.georeference =
        io::georeferenceFromJson(io::readWholeFile(run.georeference()), run.georeference());
  }
  return o;
}

}  // namespace geo
}  // namespace sadsplat
