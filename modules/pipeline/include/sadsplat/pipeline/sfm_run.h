#pragma once
/// \file sfm_run.h
/// \brief `sadsplat sfm`: a folder of photos into a scene directory that sadsplat reads as is,
/// through COLMAP's command line (Debian's `colmap`): feature extraction, matching, mapping,
/// undistortion; then the georeference from the photos' GPS (EXIF) when they carry it
/// (geo::fitGpsGeoreference), or from ground control points (gcp_list.txt,
/// geo::fitGcpGeoreference) when given.
///
/// The scene directory: images/ (undistorted), sparse/0/ (COLMAP text, PINHOLE cameras; in
/// east-north-up metres when georeferenced), georeference.json (when georeferenced),
/// sfm_report.json (stages, times, registered and unregistered photos, every photo's GPS residual
/// and every ground control point's), colmap/ (COLMAP's
/// database, its own model and the logs of every stage).

#include <ostream>
#include <string>
#include <vector>

namespace sadsplat {
namespace pipeline {

struct SfmOptions {
  std::string photos;  ///< folder of photos (JPEG, PNG, TIFF)
  std::string out;     ///< scene directory to write (created; must not hold a scene yet)
  /// auto: exhaustive up to 40 photos, spatial when most photos carry GPS, else sequential.
  std::string matcher = "auto";  ///< auto | exhaustive | sequential | spatial
  /// Longest image side for feature extraction and for the undistorted images (COLMAP's
  /// max_image_size; a 4000x3000 survey photo is then 2000x1500).
  int max_image_size = 2000;
  bool single_camera = true;  ///< one camera for every photo (one drone, one lens)
  int threads = -1;           ///< -1: every core
  /// Horizontal GPS accuracy (1 sigma, metres) the georeference starts from; 0: what the photos
  /// state in EXIF, else geo::kDefaultGpsAccuracy. The inlier distance then comes from the
  /// measured noise (geo::fitGpsGeoreference).
  double gps_accuracy = 0;
  /// OpenDroneMap's gcp_list.txt; empty: `photos`/gcp_list.txt when it exists, else none.
  std::string gcp;
  /// The spatial matcher: each photo against its k nearest photos by GPS (OpenDroneMap matches
  /// against ~8); within `match_distance` metres (0: any distance).
  int match_neighbors = 12;
  double match_distance = 0;
  /// Whether the mapper refines the focal length from its prior (EXIF, or 1.2x the longest side
  /// without one). false keeps the prior: a nadir flight over flat ground fixes the focal length
  /// only weakly, and a wrong one scales every height.
  bool refine_focal = true;
  std::string colmap = "colmap";  ///< the program
  std::ostream* progress = nullptr;
};

/// \brief What the run found.
struct SfmSummary {
  int photos = 0;
  int registered = 0;
  std::vector<std::string> unregistered;
  std::size_t points = 0;
  double mean_reprojection_error = 0;  ///< pixels, mean over the points
  bool georeferenced = false;
  /// a frame was written, but something speaks against it (georeference.json's `doubts`)
  bool georeference_doubtful = false;
  double seconds = 0;
};

/// \brief The folder COLMAP should read `photos` from: `photos_dir` itself when every photo is
/// stored upright, else `work_dir`/upright with every photo, those with an EXIF rotation
/// (io::readExifOrientation) turned upright (JPEG quality 98, no EXIF) and the others copied.
/// \param[out] rotated how many photos carried a rotation
/// \throws sadsplat::Error for an unreadable photo, or rotated photos in a build without OpenCV
std::string uprightPhotos(const std::string& photos_dir, const std::vector<std::string>& photos,
                          const std::string& work_dir, int* rotated);

/// \brief Runs the whole reconstruction.
/// \throws sadsplat::Error naming the missing program (and its Debian package), the photos
/// folder, a failed stage (with its log), or a reconstruction that registered fewer than 2 photos
SfmSummary sfmRun(const SfmOptions& options);

}  // namespace pipeline
}  // namespace sadsplat
