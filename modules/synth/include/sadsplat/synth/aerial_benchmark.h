#pragma once
/// \file aerial_benchmark.h
/// \brief The procedural 3D-AS-like benchmark: orbit views of a generated aerial world with
/// exact label and depth maps, a sparse SfM-like point cloud, written as an ordinary scene
/// directory (images/, labels/, depth/, sparse/0/, classes.json, split.json).

#include <cstdint>
#include <optional>
#include <string>
#include <vector>

#include "sadsplat/io/scene.h"
#include "sadsplat/synth/world.h"

namespace sadsplat {
namespace synth {

/// \brief How the views are flown.
enum class Capture {
  kOrbit,  ///< the paper's: oblique views on an orbit around the scene (pitch 28-56 degrees)
  kGrid,   ///< a drone-mapping mission: nadir photos on parallel lines (75 % forward overlap)
  /// The grid flown by the first half of the views, then four oblique passes by the other half:
  /// the same kind of lines at the same altitude, the camera pitched 45 degrees from nadir
  /// towards north, east, south and west in turn (view nadir + k: pass k % 4), each photo flown
  /// one altitude back from its grid position so that it looks at it.
  kGridOblique,
};

/// \brief "orbit", "grid" or "grid-oblique".
std::string captureName(Capture capture);
/// \brief The capture a name gives. \throws sadsplat::Error for another name
Capture captureFromName(const std::string& name);

/// \brief What to generate. Defaults: the full-size benchmark of the paper's split.
struct SynthOptions {
  SceneKind kind = SceneKind::kCity;
  std::uint64_t seed = 0;
  int views = 70;
  int width = 1600;
  int height = 900;
  std::vector<int> labelled = {0, 7, 28};                ///< labelled training views
  /// Instead of `labelled`: as many training views as it lists, chosen as a user is advised to
  /// choose the photos to annotate (geo::chooseAnnotationViews: those that together see most of
  /// the ground, by geometry alone).
  bool labelled_auto = false;
  std::vector<int> test = {14, 21, 35, 42, 49, 56, 63};  ///< test views (those < views)
  double horizontal_fov_deg = 60.0;
  int max_points = 20000;    ///< sparse points kept (a few thousand to tens of thousands)
  int samples_per_axis = 2;  ///< colour anti-aliasing: s x s rays per pixel (labels, depth: 1)
  int threads = 0;           ///< 0 = all hardware threads
  /// The world is tiles x tiles ordinary scenes in area (city only); view i orbits tile
  /// i % tiles^2 at the ordinary scene's distance, so each tile gets views / tiles^2 views.
  int tiles = 1;
  /// How the views are flown. kGrid: `views` photos on lines running north over 90 % of the
  /// labelled area, serpentine, the camera straight down (within ~1 degree, as a gimbal holds it)
  /// with the image's short side along the line; the lines are as many as make the spacing across
  /// ~2.5x the spacing along (so that the side overlap is ~60 %), the altitude the one that gives
  /// 75 % forward overlap over flat ground (gridAltitude()).
  Capture capture = Capture::kOrbit;

  /// \brief The `--preset demo` size: 320x180, 40 views, 4000 points.
  static SynthOptions demo(SceneKind kind, std::uint64_t seed);
  /// \brief The `--preset city-xl` benchmark: a city of 2 x 2 tiles (4x the area), 280 views of
  /// 1600x900 (70 per tile), 80,000 sparse points; per tile the ordinary split (3 labelled
  /// training views, 7 test views), so 12 labelled and 28 test views in all.
  static SynthOptions cityXl(std::uint64_t seed) { return tiledCity(seed, 2); }
  /// \brief A city of tiles x tiles ordinary scenes: 70 views of 1600x900 and 20,000 sparse
  /// points per tile, each tile with the ordinary split (3 labelled, 7 test views). tiles 2:
  /// `--preset city-xl`; tiles 4: `--preset city-xxl` (16x the area, 1,120 views).
  static SynthOptions tiledCity(std::uint64_t seed, int tiles);
};

/// \brief A grid capture's layout: lines, photos per line and the altitude above the ground.
struct GridLayout {
  int lines = 0;
  int per_line = 0;
  double altitude = 0;      ///< metres above z = 0
  double along_spacing = 0;   ///< metres between photos on a line
  double across_spacing = 0;  ///< metres between lines
  double forward_overlap = 0;  ///< share of a photo's footprint the next one sees (flat ground)
  double side_overlap = 0;     ///< the same between neighbouring lines
};
/// \brief The layout Capture::kGrid flies for `options` (its world's extent); for
/// Capture::kGridOblique the layout of its nadir half (the oblique passes fly the layout of a
/// quarter of the other half each, at the nadir half's altitude).
GridLayout gridLayout(const SynthOptions& options);
/// \brief Views flown nadir: all of a grid capture, the first half of a grid-oblique one.
int nadirViews(const SynthOptions& options);
/// \brief The pitch from nadir of the oblique passes of Capture::kGridOblique (degrees).
constexpr double kObliquePitchDeg = 45.0;

/// \brief One generated view.
struct SynthView {
  std::string name;
  io::PinholeCamera camera;
  io::Image8 rgb;            ///< 3 channels
  io::Image8 labels;         ///< class ids, 255 = outside the labelled area / sky
  std::vector<float> depth;  ///< camera z per pixel in metres, 0 = sky
};

/// \brief One sparse point with the class of the surface it was sampled from.
struct SynthPoint {
  float xyz[3];
  std::uint8_t rgb[3];
  std::uint8_t cls;
  std::vector<std::pair<int, std::array<float, 2>>> track;  ///< (view index, pixel position)
};

/// \brief The class of the topmost surface of every ground cell, looking straight down: the
/// ground truth of a semantic orthophoto (a true ortho: roofs and tree crowns, not the ground under
/// them). Cell (i, j) covers x in [x0 + i gsd, x0 + (i + 1) gsd], y in [y0 - (j + 1) gsd,
/// y0 - j gsd] of the world frame (metres, z up); its class is the one at the cell centre.
struct OrthoTruth {
  double gsd = 0.25;
  double x0 = 0, y0 = 0;
  int width = 0, height = 0;
  std::vector<std::uint8_t> classes;  ///< row-major, 255 = outside the labelled area
  std::vector<float> heights;  ///< row-major: z of that topmost surface (the true DSM), NaN = none
};

/// \brief "synth:KIND:SEED:TILES": names a generated world; toScene stores it as the scene's
/// source, so a scene cache knows the world its map-grid truth comes from.
std::string worldId(SceneKind kind, std::uint64_t seed, int tiles);
/// \brief The world a worldId names, or nothing for any other text.
std::optional<World> worldFromId(const std::string& id);

/// \brief Traces the world top-down over its labelled area at `gsd` metres per cell.
OrthoTruth orthoTruth(const World& world, double gsd = 0.25);

/// \brief A whole generated benchmark scene in memory.
struct SynthScene {
  std::vector<ClassInfo> classes;
  std::vector<SynthView> views;
  std::vector<SynthPoint> points;
  io::SplitInfo split;
  OrthoTruth ortho;    ///< the map-grid ground truth (`sadsplat eval --ortho`)
  std::string world;   ///< worldId() of the generating world (a cache's source)
  double seconds = 0;  ///< generation time
};

/// \brief Generates a scene; deterministic in the options (threads do not change the result).
/// \throws sadsplat::Error on bad options
SynthScene generate(const SynthOptions& options);

/// \brief The scene as an imported scene (what io::importScene would give for its directory:
/// the same cameras, images, label maps, split and points), e.g. to write a scene cache directly
/// on a machine without OpenCV.
io::Scene toScene(const SynthScene& scene);

/// \brief Pixel statistics: share of each class among labelled pixels, and the "effective
/// pixel" share (pixels with a class) over all views.
struct SynthStats {
  std::vector<double> class_share;
  double effective_share = 0;
};
SynthStats computeStats(const SynthScene& scene);

}  // namespace synth
}  // namespace sadsplat
