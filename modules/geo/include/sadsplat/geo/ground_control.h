#pragma once
/// \file ground_control.h
/// \brief Ground control points (GCPs) in OpenDroneMap's `gcp_list.txt`, triangulated in an SfM
/// reconstruction, and the georeference fitted to them with a share held out as check points
/// (the accuracy statement surveyors report: RMSE horizontal and vertical of the check points).
///
/// gcp_list.txt (OpenDroneMap's format): the first line is the CRS (EPSG:<code>, a PROJ string,
/// or "WGS84 UTM <zone><N|S>"); then one observation per line, `x y z px py image [name]
/// [extras...]`: the point's coordinates in that CRS (easting / longitude first), its pixel in
/// the photo `image` (top-left corner at 0, 0, as an image viewer shows the photo), an optional
/// name. Lines of one point share its name; lines without a name are grouped by equal x, y, z.
/// Blank lines and lines starting with '#' are skipped. A point whose name begins with "chk" or
/// "check" (any case) is a check point; if none is marked and there are at least 5 points, every
/// 4th point in name order is held out.

#include <array>
#include <string>
#include <vector>

#include "sadsplat/io/colmap.h"
#include "sadsplat/io/georeference.h"

namespace sadsplat {
namespace geo {

/// \brief One mark of a point on a photo.
struct GcpObservation {
  std::string image;
  double px = 0, py = 0;  ///< pixels, top-left corner of the photo at (0, 0)
  int line = 0;           ///< line in the file (1-based), for messages
};

/// \brief One ground control point.
struct GroundControlPoint {
  std::string name;
  std::array<double, 3> crs_xyz{};  ///< as in the file
  io::GeoPosition wgs84;            ///< through PROJ
  bool check = false;               ///< held out to check the fit
  std::vector<GcpObservation> observations;
};

/// \brief A parsed gcp_list.txt.
struct GcpList {
  std::string path;
  std::string crs;
  std::vector<GroundControlPoint> points;  ///< in name order
};

/// \brief Reads and checks a gcp_list.txt: the CRS, every line's fields, image names among
/// `photos` (when not empty), at least 2 marks per point on different photos, at least 3 control
/// points (not check points).
/// \throws sadsplat::Error naming the file, the line and the field
GcpList readGcpList(const std::string& path, const std::vector<std::string>& photos = {});

/// \brief Where a point is in the reconstruction: the least-squares intersection of the rays of
/// its marks on the registered photos (the camera models SIMPLE_PINHOLE, PINHOLE, SIMPLE_RADIAL,
/// RADIAL, OPENCV, their distortion undone).
struct TriangulatedGcp {
  bool ok = false;              ///< >= 2 registered marks whose rays meet in front of the cameras
  std::string why;              ///< when not ok
  std::array<double, 3> sfm{};  ///< in the model's frame
  int marks = 0;                ///< registered marks used
  double reprojection_px = 0;   ///< RMS over the marks
};
TriangulatedGcp triangulateGcp(const io::ColmapModel& model, const GroundControlPoint& point);

/// \brief One point's distance to its surveyed position under the fit.
struct GcpResidual {
  std::string name;
  bool check = false;
  double horizontal = 0, vertical = 0;  ///< metres (vertical signed: model minus survey)
  double reprojection_px = 0;
  int marks = 0;
};

/// \brief The georeference fitted to the control points (a 3D similarity, least squares) in the
/// ENU frame around `origin`, and the check points' errors under it.
struct GcpFit {
  io::Georeference georeference;
  std::vector<GcpResidual> residuals;
  std::vector<std::string> skipped;  ///< points not triangulated, with why
};

/// \brief Fits the georeference of `model` to `gcps`.
/// \throws sadsplat::Error (naming the gcp file) when fewer than 3 control points triangulate
GcpFit fitGcpGeoreference(const io::ColmapModel& model, const GcpList& gcps,
                          const io::GeoPosition& origin);

}  // namespace geo
}  // namespace sadsplat
