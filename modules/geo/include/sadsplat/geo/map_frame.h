#pragma once
/// \file map_frame.h
/// \brief Where a scene's coordinates land on a map: the projected CRS (the UTM zone of the
/// georeference's origin) or, for a scene without one, local metres in a frame whose z is the
/// scene's up. The ortho camera and the LAS export take their coordinates from here.
///
/// A georeferenced scene's frame is east-north-up (ENU) metres around its origin. Over a survey
/// (a few km at most) the map projection is, to well under a millimetre, a similarity of the
/// ENU plane: UTM is conformal, its scale and its grid convergence change by ~1e-5 per km. So the
/// orthographic camera can render straight onto the UTM grid (no resampling); the fit's residual
/// over the footprint is measured and reported. LAS points are transformed exactly, one by one.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "sadsplat/io/georeference.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace geo {

/// \brief Whether this build has GDAL (GeoTIFF, PNG, map projections).
bool haveGdal();

/// \brief The map frame: scene -> local (east', north', up) by a rotation, then the plane
/// similarity local (e, n) -> map (E, N) = k [[c, -s], [s, c]] (e, n) + (bE, bN), and
/// height = up + height_offset.
struct MapFrame {
  bool georeferenced = false;
  int epsg = 0;          ///< the CRS's EPSG code (0: local)
  std::string crs_name;  ///< e.g. "WGS 84 / UTM zone 15N" or "local metres"
  std::string wkt;       ///< OGC WKT of the CRS (a LOCAL_CS for local metres)
  std::array<double, 9> scene_to_local{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major rotation
  double k = 1, c = 1, s = 0, bE = 0, bN = 0;
  double height_offset = 0;  ///< the georeference's origin altitude (0: local)
  double fit_residual = 0;   ///< largest |exact - similarity| over the fit's samples, metres

  /// \brief Local (e, n, up) of a scene point.
  std::array<double, 3> toLocal(const std::array<double, 3>& scene_point) const;
  /// \brief Map (E, N) of a point (e, n) of the local plane (the similarity).
  std::array<double, 2> planeToMap(double e, double n) const;
  /// \brief Map (E, N, height) of a scene point (through the similarity).
  std::array<double, 3> toMap(const std::array<double, 3>& scene_point) const;
  /// \brief Ground metres per map unit squared: 1 / k^2 (UTM's scale factor is ~0.9996).
  double groundAreaPerMapArea() const { return 1.0 / (k * k); }
};

/// \brief The scene's up direction: +z for a georeferenced scene, otherwise minus the mean
/// viewing direction of its cameras (aerial surveys look down), as a unit vector.
std::array<double, 3> sceneUp(const io::Scene& scene);

/// \brief A map frame in local metres: `up` becomes z; east' is the scene's x axis made
/// orthogonal to up (or y when x is nearly parallel to up).
MapFrame localMapFrame(const std::array<double, 3>& up);

/// \brief The scene's sparse points on its ground plane: the frame localMapFrame(sceneUp(scene)),
/// each point's (e, n) in it, and the 1st and 99th percentiles of e and of n (the extent a few
/// outlying points do not stretch; the value at floor(q (count - 1)) of the sorted values).
struct GroundPoints {
  MapFrame frame;
  std::vector<double> e, n;  ///< per scene point
  double e0 = 0, e1 = 0, n0 = 0, n1 = 0;
};
/// \brief Them, for a scene with at least one sparse point.
GroundPoints groundPoints(const io::Scene& scene);

/// \brief The UTM frame of a georeferenced scene, its similarity fitted on a 5 x 5 grid over the
/// ENU rectangle [e0, e1] x [n0, n1] (the footprint).
/// \throws sadsplat::Error without GDAL, or when PROJ cannot make the transformation
MapFrame utmMapFrame(const io::Georeference& georeference, double e0, double n0, double e1,
                     double n1);

/// \brief A projected CRS: its name and OGC WKT.
struct Crs {
  std::string name;
  std::string wkt;
};

/// \brief The CRS of an EPSG code (e.g. a UTM zone's 326zz), from PROJ's database.
/// \throws sadsplat::Error without GDAL, or for a code PROJ does not know
Crs crsOfEpsg(int epsg);

/// \brief Exact map coordinates (E, N, height) of ENU points of a georeferenced scene: through
/// WGS84 and PROJ's UTM, point by point.
/// \throws sadsplat::Error without GDAL
std::vector<std::array<double, 3>> enuToUtm(const io::Georeference& georeference,
                                            const std::vector<std::array<double, 3>>& enu);

/// \brief WGS84 positions of points given in the CRS `crs`: anything GDAL's SetFromUserInput
/// takes ("EPSG:32632", a PROJ string "+proj=utm +zone=32 +datum=WGS84 +units=m", WKT) or
/// OpenDroneMap's "WGS84 UTM 32N"; x, y in the CRS's traditional GIS order (easting / longitude
/// first), z passed through as the height. `file` names the source in errors.
/// \throws sadsplat::Error naming `file` for a CRS PROJ does not know, or without GDAL
std::vector<io::GeoPosition> crsToWgs84(const std::string& crs,
                                        const std::vector<std::array<double, 3>>& xyz,
                                        const std::string& file);

/// \brief OGC WKT of the local-metres CRS (a LOCAL_CS, metres).
std::string localCrsWkt();

}  // namespace geo
}  // namespace sadsplat
