#pragma once
/// \file map_products.h
/// \brief The jobs behind `sadsplat render` (per-photo class, colour, RGB, depth and confidence
/// images, at the photos' own size, and novel views along an orbit) and `sadsplat ortho` (the
/// semantic orthophoto, class map, surface model and confidence as GeoTIFF, with class areas),
/// and `sadsplat eval --ortho` (the class map scored against a map-grid ground truth).

#include <array>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

namespace sadsplat {
namespace pipeline {

/// \brief Options of `sadsplat render`.
struct RenderRunOptions {
  std::string run;            ///< run directory
  std::string out;            ///< output directory (created)
  std::string views = "all";  ///< all | train | test | comma-separated image names
  int width = 0, height = 0;  ///< --size WxH (0: see scale)
  double scale = 0;           ///< --scale S of the imported size (0: the original photos')
  std::vector<std::string> outputs{"class", "colour", "rgb", "depth", "confidence"};
  std::string path;  ///< "orbit:N": N novel views around the scene instead
  std::ostream* progress = nullptr;
};

/// \brief Renders the views; returns the number of images written. Files:
/// OUT/class/NAME.png (8-bit class ids, 255 = none), OUT/colour/NAME.png (class palette),
/// OUT/rgb/NAME.png, OUT/depth/NAME.tif (float32 camera z, 0 = none), OUT/confidence/NAME.png
/// (8-bit, 255 x the decoded class's cosine, Trainer::classCosines), NAME = the image name without
/// extension. \throws sadsplat::Error for unknown views or outputs, bad sizes, an unwritable OUT
int renderRun(const RenderRunOptions& options);

/// \brief Options of `sadsplat ortho`.
struct OrthoRunOptions {
  std::string run;
  std::string out;
  std::optional<double>
      gsd;  ///< metres per pixel (> 0); none = the photos' median ground sample distance
  std::optional<std::array<double, 4>> bounds;  ///< xmin, ymin, xmax, ymax in the map CRS
  std::string height = "first";      ///< --height first|blend (ortho_render.h, OrthoSurface)
  /// --class-from views|blend|first (OrthoClassSource): the views' classes gave a class map higher
  /// than or equal to the blend's on 16 of 16 synth runs (orbits +2.2 to +4.5 points;
  /// docs/measurements/cloud_3d).
  std::string class_from = "views";
  int min_views = 0;      ///< --min-views: cells fewer training photos see are nodata (0: off)
  double min_spread = 0;  ///< --min-spread DEG (OrthoRenderOptions::min_spread_degrees)
  double depth_tolerance = 0.02;  ///< --depth-tolerance (OrthoRenderOptions::depth_tolerance)
  double on_surface = 0;          ///< --on-surface M (OrthoRenderOptions::max_surface_gap; 0: off)
  /// --raised-check SHARE (OrthoRenderOptions::raised_share; 0: off). 0.33 of 0.25 / 0.33 / 0.5
  /// on the benchmark's 34 runs (docs/measurements/cloud_3d): every class map gained.
  double raised_check = 0.33;
  /// --pit-depth M (OrthoRenderOptions::pit_depth; 0: off): ground-class cells more than M below
  /// the ground classes around them take their height (docs/measurements/cloud_3d).
  double pit_depth = 1.0;
  /// --spike-height M (OrthoRenderOptions::spike_height; 0: off): ground-class cells more than
  /// M above the ground classes around them take their height. Off: with it (1 m, clearance
  /// 4 m) the DSM's RMSE fell on 6 of 8 synth runs (city, country, port; port orbit 4.4 ->
  /// 2.6 m) but rose on a city mission whose roofs the class map calls paved (roofs 0.95 ->
  /// 2.78 m; docs/measurements/cloud_3d).
  double spike_height = 0;
  /// --spike-clearance M (OrthoRenderOptions::spike_clearance): 4 of 0 / 1 / 2 / 4 m kept the
  /// roofs best on those runs.
  double spike_clearance = 4;
  double ground_window = 20;  ///< --ground-window M (OrthoRenderOptions::ground_window)
  /// --vectors: classes (names) whose objects go to OUT/vectors.gpkg as polygons (none: no file)
  std::vector<std::string> vectors;
  /// --object-step M: a class's regions are cut into objects where the DSM steps by more than M
  /// between neighbouring cells (geo/map_objects.h; 0: the plain regions); what --vectors writes
  /// and `eval --ortho` scores as building objects.
  double object_step = 1.5;
  /// --trim: classes (names) whose objects on the map are trimmed to the hull of their
  /// Gaussians (OrthoRenderOptions::trim_classes; cut at object_step); "auto": the class named
  /// building where the model has one; "none" (or empty): off. On ten synth city runs (orbit and
  /// mission) the trim raised every class map (+0.3 to +1.0 points) and halved the mean building
  /// area error (15 -> 7.6 %; docs/measurements/cloud_3d).
  std::vector<std::string> trim = {"auto"};
  /// --trim-whole-under N: objects of the trimmed classes with fewer than N opaque Gaussians of
  /// their class over them take the classes around them whole (0: kept)
  int trim_whole_under = 0;
  /// --object-clouds: with `vectors`, OUT/objects/ holds each object's Gaussians (those of its
  /// class from the training views, opacity >= object_min_opacity, centre over one of its cells)
  /// as object_<id>.pcd, every field, in the model's frame, ids as vectors.gpkg's object_id, and
  /// objects.csv (object_id, class_id, class, gaussians, centroid, map x / y, height_m, file)
  bool object_clouds = false;
  /// --object-min-opacity: the opaque Gaussians (the surfaces a PCL user measures; what
  /// `eval --ortho` scores); 0 keeps the translucent ones too (the object as a splat viewer shows
  /// it)
  double object_min_opacity = 0.5;
  std::ostream* progress = nullptr;
};

/// \brief Writes OUT/orthophoto.tif (RGBA), classes.tif (class ids with a colour table, 255 =
/// nodata), dsm.tif (float32 height, -9999 = nodata), confidence.tif (float32, -1 = nodata),
/// their PNG previews, classes.csv (pixels, area in m^2 and share per class) and ortho.json (the
/// grid, CRS and fit); with `vectors`, vectors.gpkg (geo/vector_files.h: the classes' objects,
/// geo/map_objects.h, as polygons simplified to one cell, those under four cells left out); with
/// `object_clouds` also OUT/objects/ (OrthoRunOptions::object_clouds). Returns
/// a short summary for the terminal.
std::string orthoRun(const OrthoRunOptions& options);

/// \brief `sadsplat eval RUN --ortho`: renders the class map on the grid of the scene's
/// ortho_truth.json (written by `sadsplat synth`) and scores it: mIoU, per-class IoU, and the
/// area error per class. The map is rendered as `ortho` renders it with `render`'s height,
/// class_from and min_views; on `scene_override` when given (a copied run whose scene moved).
/// Writes RUN/ortho_metrics.json and returns its text.
std::string evalOrthoRun(const std::string& run_dir, const std::string& truth_json = "",
                         const OrthoRunOptions& render = {},
                         const std::string& scene_override = "");

}  // namespace pipeline
}  // namespace sadsplat
