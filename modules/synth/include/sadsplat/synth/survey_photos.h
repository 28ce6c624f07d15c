#pragma once
/// \file survey_photos.h
/// \brief A generated scene's views as a drone survey's photos (needs OpenCV): JPEGs with the
/// GPS a camera writes (its noise chosen), the focal length in EXIF, and optionally ground control
/// points in OpenDroneMap's gcp_list.txt, so that `sadsplat sfm` runs on them as on real photos
/// and its frame can be scored against the known world.

#include <cstdint>
#include <string>

#include "sadsplat/io/georeference.h"
#include "sadsplat/synth/aerial_benchmark.h"

namespace sadsplat {
namespace synth {

/// \brief How the photos' GPS and the control points are made.
struct SurveyPhotoOptions {
  /// Where the world is: its x, y, z are east, north, up metres around this place.
  io::GeoPosition place{47.3769, 8.5417, 420.0};
  double horizontal_noise = 0;  ///< GPS: metres, 1 sigma per horizontal axis
  double altitude_offset = 0;   ///< metres added to every GPS altitude
  double altitude_wander = 0;   ///< amplitude (metres) of a slow wander: sin(0.3 * photo index)
  double altitude_noise = 0;    ///< metres, 1 sigma
  std::uint64_t seed = 1;
  /// > 0: gcp_list.txt (EPSG:4326) with about this many ground points on a grid over 70 % of the
  /// world, each marked on every photo that sees it unoccluded, with `mark_noise_px` of noise.
  int ground_control_points = 0;
  double mark_noise_px = 0.5;
};

/// \brief Writes `dir`/<view stem>.jpg (quality 95, EXIF GPS and FocalLengthIn35mmFilm) and, when
/// asked, `dir`/gcp_list.txt. Returns the number of control points written.
/// \throws sadsplat::Error when a file cannot be written
int writeSurveyPhotos(const SynthScene& scene, const SurveyPhotoOptions& options,
                      const std::string& dir);

}  // namespace synth
}  // namespace sadsplat
