#include "sadsplat/geo/map_frame.h"
#include "sadsplat/geo/geodesy.h"

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "sadsplat/common/error.h"

#if SADSPLAT_HAVE_GDAL
#include <cpl_conv.h>
#include <ogr_spatialref.h>
#endif

namespace sadsplat {
namespace geo {
namespace {

using Vec3 = std::array<double, 3>;

Vec3 normalised(const Vec3& v) {
  const double n = std::sqrt(v[0] * v[0] + v[1] * v[1] + v[2] * v[2]);
  return {v[0] / n, v[1] / n, v[2] / n};
}

Vec3 cross(const Vec3& a, const Vec3& b) {
  return {a[1] * b[2] - a[2] * b[1], a[2] * b[0] - a[0] * b[2], a[0] * b[1] - a[1] * b[0]};
}

double dot(const Vec3& a, const Vec3& b) { return a[0] * b[0] + a[1] * b[1] + a[2] * b[2]; }

#if SADSPLAT_HAVE_GDAL
struct TransformDeleter {
  void operator()(OGRCoordinateTransformation* t) const {
    OGRCoordinateTransformation::DestroyCT(t);
  }
};
using Transform = std::unique_ptr<OGRCoordinateTransformation, TransformDeleter>;

OGRSpatialReference utmReference(int epsg) {
  OGRSpatialReference utm;
  if (utm.importFromEPSG(epsg) != OGRERR_NONE) {
    throw Error("<georeference>", "epsg_utm", "an EPSG code PROJ knows (its proj.db)",
                std::to_string(epsg) + " (" + CPLGetLastErrorMsg() + ")");
  }
  utm.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  return utm;
}

Transform wgs84ToUtm(int epsg) {
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);  // lon, lat
  const OGRSpatialReference utm = utmReference(epsg);
  Transform t(OGRCreateCoordinateTransformation(&wgs84, &utm));
  if (!t) {
    throw Error("<georeference>", "epsg_utm", "a WGS84 -> UTM transformation PROJ can make",
                CPLGetLastErrorMsg());
  }
  return t;
}
#endif

#if !SADSPLAT_HAVE_GDAL
[[noreturn]] void noGdal(const char* what) {
  throw Error("<build>", what, "a sadsplat build with GDAL (Debian: libgdal-dev)",
              "a build without it");
}
#endif

}  // namespace

bool haveGdal() { return SADSPLAT_HAVE_GDAL != 0; }

Vec3 MapFrame::toLocal(const Vec3& p) const {
  const auto& R = scene_to_local;
  return {R[0] * p[0] + R[1] * p[1] + R[2] * p[2], R[3] * p[0] + R[4] * p[1] + R[5] * p[2],
          R[6] * p[0] + R[7] * p[1] + R[8] * p[2]};
}

std::array<double, 2> MapFrame::planeToMap(double e, double n) const {
  return {k * (c * e - s * n) + bE, k * (s * e + c * n) + bN};
}

Vec3 MapFrame::toMap(const Vec3& p) const {
  const Vec3 l = toLocal(p);
  const auto m = planeToMap(l[0], l[1]);
  return {m[0], m[1], l[2] + height_offset};
}

Vec3 sceneUp(const io::Scene& scene) {
  if (scene.georeference) return {0, 0, 1};
  Vec3 sum{0, 0, 0};
  for (const io::View& v : scene.views) {
    const auto R = v.camera.rotation();  // world-to-camera; row 2 = viewing direction in world
    for (int j = 0; j < 3; ++j) sum[j] -= R[6 + j];
  }
  const double n = std::sqrt(dot(sum, sum));
  if (!(n > 1e-9)) return {0, 0, 1};  // cameras looking every way: keep the frame's z
  return {sum[0] / n, sum[1] / n, sum[2] / n};
}

MapFrame localMapFrame(const Vec3& up_in) {
  const Vec3 up = normalised(up_in);
  Vec3 axis = std::abs(up[0]) < 0.9 ? Vec3{1, 0, 0} : Vec3{0, 1, 0};
  const double d = dot(axis, up);
  const Vec3 east = normalised({axis[0] - d * up[0], axis[1] - d * up[1], axis[2] - d * up[2]});
  const Vec3 north = cross(up, east);
  MapFrame f;
  f.crs_name = "local metres (the scene's frame, z up)";
  f.wkt = localCrsWkt();
  f.scene_to_local = {east[0], east[1], east[2], north[0], north[1], north[2], up[0], up[1], up[2]};
  return f;
}

namespace {
// The value at quantile q (0..1) of `values` (sorted in place).
double sortedQuantile(std::vector<double>& values, double q) {
  std::sort(values.begin(), values.end());
  return values[static_cast<std::size_t>(std::floor(q * (values.size() - 1)))];
}
}  // namespace

GroundPoints groundPoints(const io::Scene& scene) {
  GroundPoints g;
  g.frame = localMapFrame(sceneUp(scene));
  const std::size_t np = scene.points.size();
  g.e.resize(np);
  g.n.resize(np);
  for (std::size_t i = 0; i < np; ++i) {
    const auto& x = scene.points[i].xyz;
    const auto local = g.frame.toLocal({x[0], x[1], x[2]});
    g.e[i] = local[0];
    g.n[i] = local[1];
  }
  if (np == 0) return g;
  std::vector<double> sorted = g.e;
  g.e0 = sortedQuantile(sorted, 0.01);
  g.e1 = sortedQuantile(sorted, 0.99);
  sorted = g.n;
  g.n0 = sortedQuantile(sorted, 0.01);
  g.n1 = sortedQuantile(sorted, 0.99);
  return g;
}

std::string localCrsWkt() {
  return "LOCAL_CS[\"sadsplat local metres\",LOCAL_DATUM[\"scene frame\",0],"
         "UNIT[\"metre\",1,AUTHORITY[\"EPSG\",\"9001\"]],AXIS[\"Easting\",EAST],"
         "AXIS[\"Northing\",NORTH]]";
}

Crs crsOfEpsg(int epsg) {
#if SADSPLAT_HAVE_GDAL
  const OGRSpatialReference reference = utmReference(epsg);
  Crs crs;
  crs.name = reference.GetName() ? reference.GetName() : "EPSG:" + std::to_string(epsg);
  char* wkt = nullptr;
  reference.exportToWkt(&wkt);
  crs.wkt = wkt ? wkt : "";
  CPLFree(wkt);
  return crs;
#else
  (void)epsg;
  noGdal("map projection");
#endif
}

std::vector<io::GeoPosition> crsToWgs84(const std::string& crs, const std::vector<Vec3>& xyz,
                                        const std::string& file) {
#if SADSPLAT_HAVE_GDAL
  OGRSpatialReference from;
  // OpenDroneMap's own form: "WGS84 UTM <zone><N|S>".
  int zone = 0;
  char hemisphere = 0;
  std::string text = crs;
  if (std::sscanf(crs.c_str(), "WGS84 UTM %d%c", &zone, &hemisphere) == 2 && zone >= 1 &&
      zone <= 60 && (hemisphere == 'N' || hemisphere == 'S')) {
    text = "EPSG:" + std::to_string((hemisphere == 'N' ? 32600 : 32700) + zone);
  }
  CPLErrorReset();
  CPLPushErrorHandler(CPLQuietErrorHandler);
  const OGRErr parsed = from.SetFromUserInput(text.c_str());
  CPLPopErrorHandler();
  if (parsed != OGRERR_NONE) {
    throw Error(file, "CRS (first line)",
                "EPSG:<code>, a PROJ string (+proj=utm +zone=..) or WGS84 UTM <zone><N|S>", crs);
  }
  from.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  OGRSpatialReference wgs84;
  wgs84.SetWellKnownGeogCS("WGS84");
  wgs84.SetAxisMappingStrategy(OAMS_TRADITIONAL_GIS_ORDER);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  Transform t(OGRCreateCoordinateTransformation(&from, &wgs84));
  CPLPopErrorHandler();
  if (!t) {
    throw Error(file, "CRS (first line)", "a CRS PROJ can transform to WGS84", crs);
  }
  std::vector<double> x(xyz.size()), y(xyz.size()), z(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) x[i] = xyz[i][0], y[i] = xyz[i][1], z[i] = xyz[i][2];
  std::vector<int> ok(xyz.size(), 0);
  CPLPushErrorHandler(CPLQuietErrorHandler);
  const bool done = xyz.empty() || t->Transform(static_cast<int>(xyz.size()), x.data(), y.data(),
                                                z.data(), ok.data());
  CPLPopErrorHandler();
  std::vector<io::GeoPosition> out(xyz.size());
  for (std::size_t i = 0; i < xyz.size(); ++i) {
    if (!done || !ok[i] || !(std::abs(y[i]) <= 90) || !(std::abs(x[i]) <= 180)) {
      throw Error(file, "coordinates", "positions in the CRS " + crs,
                  std::to_string(xyz[i][0]) + " " + std::to_string(xyz[i][1]) +
                      " (not transformable to WGS84)");
    }
    out[i] = {y[i], x[i], z[i]};
  }
  return out;
#else
  (void)crs;
  (void)xyz;
  (void)file;
  noGdal("coordinate reference systems");
#endif
}

std::vector<Vec3> enuToUtm(const io::Georeference& g, const std::vector<Vec3>& enu) {
#if SADSPLAT_HAVE_GDAL
  const Transform t = wgs84ToUtm(g.epsg_utm);
  std::vector<double> x(enu.size()), y(enu.size()), z(enu.size());
  for (std::size_t i = 0; i < enu.size(); ++i) {
    const io::GeoPosition p = geo::fromEnu(enu[i], g.origin);
    x[i] = p.longitude;
    y[i] = p.latitude;
    z[i] = p.altitude;
  }
  std::vector<int> ok(enu.size(), 0);
  if (!enu.empty() &&
      !t->Transform(static_cast<int>(enu.size()), x.data(), y.data(), z.data(), ok.data())) {
    throw Error("<georeference>", "epsg_utm", "positions PROJ can project", CPLGetLastErrorMsg());
  }
  std::vector<Vec3> out(enu.size());
  for (std::size_t i = 0; i < enu.size(); ++i) out[i] = {x[i], y[i], z[i]};
  return out;
#else
  (void)g;
  (void)enu;
  noGdal("map projection");
#endif
}

MapFrame utmMapFrame(const io::Georeference& g, double e0, double n0, double e1, double n1) {
#if SADSPLAT_HAVE_GDAL
  MapFrame f;
  f.georeferenced = true;
  f.epsg = g.epsg_utm;
  const Crs crs = crsOfEpsg(g.epsg_utm);
  f.crs_name = crs.name;
  f.wkt = crs.wkt;
  f.height_offset = g.origin.altitude;
  // Least squares for E = a e - b n + tx, N = b e + a n + ty on a 5 x 5 grid (at height 0).
  std::vector<Vec3> samples;
  for (int i = 0; i < 5; ++i) {
    for (int j = 0; j < 5; ++j) {
      samples.push_back({e0 + (e1 - e0) * i / 4.0, n0 + (n1 - n0) * j / 4.0, 0.0});
    }
  }
  const std::vector<Vec3> exact = enuToUtm(g, samples);
  // Normal equations of the 4 unknowns; centred sums make them diagonal.
  double me = 0, mn = 0, mE = 0, mN = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    me += samples[i][0];
    mn += samples[i][1];
    mE += exact[i][0];
    mN += exact[i][1];
  }
  const double count = static_cast<double>(samples.size());
  me /= count, mn /= count, mE /= count, mN /= count;
  double num_a = 0, num_b = 0, den = 0;
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const double e = samples[i][0] - me, n = samples[i][1] - mn;
    const double E = exact[i][0] - mE, N = exact[i][1] - mN;
    num_a += e * E + n * N;
    num_b += e * N - n * E;
    den += e * e + n * n;
  }
  const double a = den > 0 ? num_a / den : 1, b = den > 0 ? num_b / den : 0;
  f.k = std::sqrt(a * a + b * b);
  f.c = a / f.k;
  f.s = b / f.k;
  f.bE = mE - (a * me - b * mn);
  f.bN = mN - (b * me + a * mn);
  for (std::size_t i = 0; i < samples.size(); ++i) {
    const Vec3 m = f.toMap(samples[i]);
    f.fit_residual = std::max(f.fit_residual, std::hypot(m[0] - exact[i][0], m[1] - exact[i][1]));
  }
  return f;
#else
  (void)g, (void)e0, (void)n0, (void)e1, (void)n1;
  noGdal("map projection");
#endif
}

}  // namespace geo
}  // namespace sadsplat
