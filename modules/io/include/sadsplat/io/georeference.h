#pragma once
/// \file georeference.h
/// \brief Where a scene is on the Earth: photo GPS positions (EXIF), WGS84 <-> local east-north-up
/// metres, and the similarity that takes an SfM reconstruction's arbitrary frame into that local
/// frame (metres, z up). No OpenCV, no LibTorch.

#include <array>
#include <optional>
#include <string>
#include <vector>

namespace sadsplat {
namespace io {

/// \brief A WGS84 position: degrees, metres above the ellipsoid (EXIF altitudes are usually above
/// sea level; the difference is a constant offset of the local frame's z, not a distortion).
struct GeoPosition {
  double latitude = 0;   ///< degrees, north positive
  double longitude = 0;  ///< degrees, east positive
  double altitude = 0;   ///< metres
  /// Horizontal 1-sigma metres the receiver states (EXIF GPSHPositioningError, else GPSDOP x
  /// 3 m, a civil receiver's range error); 0: none stated.
  double horizontal_accuracy = 0;
};

/// \brief The GPS position in a photo's EXIF (GPSLatitude/Longitude/Altitude and their Ref tags),
/// or nothing when it has none. Needs libexif (SADSPLAT_HAVE_EXIF); without it always nothing.
/// \throws sadsplat::Error naming the file when its GPS tags are present but malformed (a latitude
/// beyond +-90 degrees, a rational with a zero denominator)
std::optional<GeoPosition> readExifGps(const std::string& path);
/// \brief Whether this build reads EXIF (it has libexif).
bool haveExif();

/// \brief A JPEG's bytes with an EXIF APP1 segment holding `gps` inserted after the SOI marker
/// (TIFF little endian, IFD0 with a GPS IFD pointer; what cameras write), and, when
/// `focal_length_35mm` > 0, an Exif IFD with FocalLengthIn35mmFilm (mm; COLMAP takes its focal
/// length prior from it). For test data and `synth`'s photos.
/// \throws sadsplat::Error when `jpeg` does not start with an SOI marker
std::vector<unsigned char> jpegWithExifGps(const std::vector<unsigned char>& jpeg,
                                           const GeoPosition& gps, int focal_length_35mm = 0);

/// \brief EPSG code of the WGS84 / UTM zone that holds `p` (326zz north, 327zz south; the
/// standard 6-degree zones, without the Norway / Svalbard exceptions).
int utmEpsg(const GeoPosition& p);

/// \brief A similarity x' = scale * R x + t.
struct Similarity {
  double scale = 1;
  std::array<double, 9> rotation{1, 0, 0, 0, 1, 0, 0, 0, 1};  ///< row-major
  std::array<double, 3> translation{0, 0, 0};
  std::array<double, 3> apply(const std::array<double, 3>& x) const;
};

/// \brief A scene's georeference: its frame is east-north-up metres around `origin`.
struct Georeference {
  GeoPosition origin;
  int epsg_utm = 0;         ///< the UTM zone of the origin, for GIS outputs
  Similarity sfm_to_local;  ///< how the SfM frame was taken into the local frame
  int photos_with_gps = 0;  ///< photos whose GPS took part in the fit
  int inliers = 0;          ///< of those, within the inlier distance under the fit
  /// whether >= 3 photos agreed within the inlier distance; false: the fit of all photos' GPS,
  /// which can be off by its RMS (the reconstruction and the GPS disagree)
  bool consensus = true;
  double rms_metres = 0;  ///< RMS distance of the fitted photos' camera centres to their GPS

  // How the frame was made and what to think of it (absent from files of before 2026-11-28:
  // then empty / 0 / -1).
  /// "nadir views", "ground plane" (the up direction from the scene), "gps 3D fit", or
  /// "ground control points"
  std::string up_source;
  double gps_accuracy_metres = 0;    ///< horizontal 1 sigma the fit started from (stated/assumed)
  double gps_noise_metres = 0;       ///< horizontal 1 sigma measured on the agreeing photos
  double inlier_metres = 0;          ///< the final inlier distance (horizontal)
  double horizontal_rms_metres = 0;  ///< over the agreeing photos (or control points)
  double vertical_rms_metres = 0;    ///< likewise, after the median altitude offset
  double scale_uncertainty = 0;      ///< relative 1 sigma of the scale from the GPS noise
  double ground_tilt_deg = -1;  ///< the sparse points' ground plane vs z after the fit; -1: none
  double views_tilt_deg = -1;   ///< minus the mean viewing direction vs z; -1: views not nadir
  /// Why the frame is doubtful, one sentence each; empty: nothing found against it.
  std::vector<std::string> doubts;
  int control_points = 0;  ///< ground control points the frame was fitted to (gcp_list.txt)
  int check_points = 0;    ///< ground control points held out to check it
  double check_rmse_horizontal = -1;  ///< metres over the check points; -1: none
  double check_rmse_vertical = -1;    ///< metres over the check points; -1: none

  /// \brief Whether nothing speaks against the frame.
  bool trustworthy() const { return consensus && doubts.empty(); }
};

/// \brief georeference.json text (every field above).
std::string georeferenceToJson(const Georeference& g);
/// \brief Reads georeference.json text.
/// \throws sadsplat::Error naming `origin` and the field
Georeference georeferenceFromJson(const std::string& text, const std::string& origin);

}  // namespace io
}  // namespace sadsplat
