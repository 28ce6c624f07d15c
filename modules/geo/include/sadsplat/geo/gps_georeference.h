#pragma once
/// \file gps_georeference.h
/// \brief The georeference of an SfM reconstruction from its photos' GPS, as consumer GPS
/// allows: the up direction from the scene (a nadir survey looks down; the ground of the sparse
/// points is level), the horizontal similarity (scale, heading, east / north shift) fitted
/// robustly to the GPS with a threshold from the GPS's stated accuracy and then from its measured
/// noise, the altitude only as the median offset (camera GPS altitudes wander by tens of metres).
/// A full 3D fit of the GPS is the fallback when the scene gives no up.
///
/// Why not the 3D similarity of the GPS alone: a flight at one height puts the camera centres on
/// a plane, and the tilt of that plane is then set by the GPS altitudes alone; metres of altitude
/// noise over a few hundred metres of flight tilt the whole model by degrees (19 degrees on a
/// 75-photo survey with camera GPS). OpenSfM and OpenDroneMap treat camera GPS likewise.

#include <array>
#include <optional>
#include <string>
#include <vector>

#include "sadsplat/io/georeference.h"

namespace sadsplat {
namespace geo {

/// \brief Horizontal GPS accuracy (1 sigma, metres) assumed for photos that state none.
constexpr double kDefaultGpsAccuracy = 5.0;

/// \brief One registered photo as the fit sees it.
struct GpsPhoto {
  std::string name;
  std::array<double, 3> centre{};   ///< camera centre in the SfM frame
  std::array<double, 3> viewing{};  ///< unit viewing direction (camera +z) in the SfM frame
  std::optional<std::array<double, 3>> gps;  ///< its GPS in ENU metres around the origin
  double stated_accuracy = 0;  ///< horizontal 1-sigma metres the photo states (EXIF), 0: none
};

/// \brief An up direction found in the scene, in the SfM frame.
struct UpCue {
  bool found = false;
  std::array<double, 3> up{0, 0, 1};  ///< unit
  /// views: the mean resultant length of the viewing directions (1: all parallel);
  /// ground: the share of the sparse points within the plane's distance
  double quality = 0;
};

/// \brief Minus the mean viewing direction, found when the views are nadir: their mean resultant
/// length is at least cos(20 degrees) (a gimbal at -90 degrees gives ~1, an orbit of oblique
/// views ~0.7 or a biased mean on part of an orbit).
UpCue upFromViews(const std::vector<std::array<double, 3>>& viewing);

/// \brief The normal of the dominant plane of the sparse points (RANSAC, then least squares on
/// its points), turned towards the cameras; found when at least 15 % of the points lie within
/// 1 % of the points' spread of it. Deterministic (a fixed seed).
UpCue upFromGround(const std::vector<std::array<double, 3>>& points,
                   const std::array<double, 3>& camera_mean);

/// \brief What the fit is told.
struct GpsFitOptions {
  /// Horizontal GPS accuracy, 1 sigma metres; 0: the photos' own (EXIF) where they state one,
  /// else kDefaultGpsAccuracy. RANSAC takes 3.44x this (the 2D radius of 99.73 %, as 3 sigma in
  /// 1D) as its first inlier distance; the final one is 3.44x the noise measured on the agreeing
  /// photos, never below this.
  double accuracy = 0;
};

/// \brief One photo's distance to its GPS under the fit.
struct GpsResidual {
  std::string photo;
  double horizontal = 0;  ///< metres, east-north
  double vertical = 0;    ///< metres, up (after the median altitude offset)
  bool inlier = false;
};

/// \brief The fit and what to think of it.
struct GpsFit {
  io::Georeference georeference;  ///< origin, EPSG, similarity and the statements below
  std::vector<GpsResidual> residuals;
};

/// \brief Fits the georeference. `origin` is the ENU origin of the photos' `gps`.
/// \throws sadsplat::Error when fewer than 3 photos carry GPS, or their positions are
/// degenerate (all on one point)
GpsFit fitGpsGeoreference(const std::vector<GpsPhoto>& photos,
                          const std::vector<std::array<double, 3>>& points,
                          const io::GeoPosition& origin, const GpsFitOptions& options = {});

/// \brief Degrees between the unit vectors `a` and `b`.
double angleDegrees(const std::array<double, 3>& a, const std::array<double, 3>& b);

}  // namespace geo
}  // namespace sadsplat
