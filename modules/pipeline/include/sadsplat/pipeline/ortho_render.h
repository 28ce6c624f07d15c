#pragma once
/// \file ortho_render.h
/// \brief Top-down orthographic renders of a trained model onto a north-up map grid: the true
/// orthophoto, the class map, the surface height and the class confidence, tile by tile (the
/// features of a large grid do not fit in memory at once).

#include <array>
#include <cstdint>
#include <optional>
#include <ostream>
#include <string>
#include <vector>

#include "sadsplat/gaussians/rasterizer.h"
#include "sadsplat/gaussians/trainer.h"
#include "sadsplat/geo/map_frame.h"

namespace sadsplat {
namespace pipeline {

/// \brief A north-up grid in a map frame: pixel (i, j) covers map x in [x0 + i gsd,
/// x0 + (i + 1) gsd] and y in [y0 - (j + 1) gsd, y0 - j gsd] (GDAL's geotransform).
struct OrthoGrid {
  geo::MapFrame frame;
  double x0 = 0, y0 = 0, gsd = 1;
  int width = 0, height = 0;
  double top = 0;  ///< local height of the camera plane (above every Gaussian)
};

/// \brief The grid over the model's ground footprint: the 1st to 99th percentile of its
/// Gaussians' centres (those of opacity >= 0.1 that some training photo shows in the middle
/// kFootprintImageShare of its width and height: what the capture looks at, not the far terrain
/// an oblique photo shows near its edge) in map x and y, 2 % margin, corners snapped to
/// whole multiples of `gsd`. A georeferenced scene gets its UTM frame (fitted over that
/// footprint), any other its local-metres frame. `bounds` (x0, y0, x1, y1 in the frame's map
/// units) replaces the footprint.
/// \throws sadsplat::Error for gsd <= 0, a grid over 40,000 pixels a side or an empty model
constexpr double kFootprintImageShare = 0.8;
OrthoGrid footprintGrid(const gaussians::Trainer& trainer, const io::Scene& scene, double gsd,
                        const std::optional<std::array<double, 4>>& bounds = std::nullopt);

/// \brief A camera plane above every Gaussian of the model in `frame`: its highest centre in
/// local up, + 1 unit.
double orthoTop(const gaussians::Trainer& trainer, const geo::MapFrame& frame);

/// \brief The orthographic camera of the grid's pixels [x_off, x_off + w) x [y_off, y_off + h).
gaussians::RasterCamera orthoCamera(const OrthoGrid& grid, int x_off, int y_off, int w, int h);

/// \brief Where along a cell's vertical ray the DSM takes its height from.
enum class OrthoSurface {
  /// The first surface: where the transmittance along the ray falls below 0.5
  /// (gaussians/surface_layer.h).
  kFirst,
  /// The blend through every Gaussian on the ray: the expected depth (a floater or an
  /// overhanging edge pulls it towards itself).
  kBlend,
};

/// \brief What a cell's class is made of.
enum class OrthoClassSource {
  /// The class with the most blending weight along the ray, each Gaussian counted as the class
  /// the training views give it (OrthoRenderOptions::gaussian_classes, labelled_cloud.h), not as
  /// its feature decodes top-down. Confidence: that class's share of the weight.
  kViews,
  /// The class of the feature composited through every Gaussian on the ray.
  kBlend,
  /// The class of the feature composited in front of the first surface (OrthoSurface::kFirst).
  kFirst,
};

/// \brief How the map is rendered.
struct OrthoRenderOptions {
  /// The DSM: the first surface's height halves the median error of the blend's (measured on
  /// synth scenes, docs/measurements/cloud_3d).
  OrthoSurface height = OrthoSurface::kFirst;
  /// The class map: the blend's class scores 1.5-5 points mIoU above the first surface's on the
  /// same runs (the features are trained as blends). kViews scores higher still but needs
  /// gaussian_classes (the CLI's default, map_products.h); here the blend needs nothing.
  OrthoClassSource classes = OrthoClassSource::kBlend;
  /// A covered cell whose surface point fewer than this many of `cameras` see unoccluded is
  /// nodata (gaussians::seenUnoccluded against each camera's depth render): a surface only one
  /// photo sees has no depth from the photos (the survey's edges), one no photo sees (an alley
  /// between tall buildings) is a guess. 0 (the default): every covered cell is kept. On synth
  /// orbits 2 removed the invented surfaces (14-24 % of the map); on a real 18-photo survey
  /// trained briefly on the CPU it left 68 % of the map nodata (the model's depths disagree
  /// between photos by more than the tolerance), so it is asked for, not assumed.
  int min_views = 0;
  /// Not on by default (measured on one CPU model only): a covered cell is also nodata when the
  /// photos that see it do so from one side: the spread of their horizontal viewing directions
  /// (2 acos of the mean resultant length of the unit vectors: 2a for photos within +-a of one
  /// azimuth, 180 for two opposite ones) is below this many degrees. 0: off.
  double min_spread_degrees = 0;
  /// A photo sees a cell's surface point when the depth it renders there agrees within this
  /// share of the point's depth (gaussians::seenUnoccluded).
  double depth_tolerance = 0.02;
  /// Not on by default: the map is made of the Gaussians at most this far (scene units) from the
  /// surface the training cameras render where they draw (Trainer::renderedDepthResiduals
  /// against the expected depth, SurfaceDepth::kExpected: on the maps it kept more roofs than the
  /// cloud's median-depth check); floaters and Gaussians off the surfaces drop out of the
  /// orthophoto, the class map and the DSM. 0: every Gaussian.
  double max_surface_gap = 0;
  /// The class map's raised classes (those whose cells stand at a median of
  /// at least raised_height above the ground: buildings, trees) do not lie on the ground. A cell
  /// of one lower than raised_share x its class's median height above the ground takes the most
  /// likely ground class (median below half raised_height: roads, grass, not cars;
  /// geo/ground_model.h; the ground from the DSM in windows of
  /// ground_window). On synth orbits the cells the photos never see (passages between a
  /// block's buildings) carry the building class at ground height. 0: off (here; `ortho` and
  /// `eval --ortho` ask for 0.33, map_products.h).
  double raised_share = 0;
  /// The DSM's cells of a ground class (those whose median stands below half raised_height
  /// above the ground: roads, grass, water) more than this below the median height of the ground
  /// classes' cells around them (windows of ground_window) take that height: the first surface
  /// fell through thin ground Gaussians to those under the ground (geo::findGroundPits). Needs
  /// the ground model, so it is skipped where the raised check is (too few cells near the
  /// ground). 0: off (here; `ortho` and `eval --ortho` ask for 1, map_products.h).
  double pit_depth = 0;
  /// DSM cells of a ground class more than this above the level of the ground classes around
  /// them (windows of ground_window) take that level, after the trim: a road's height is the
  /// ground's, not a floater's over it (geo::findGroundSpikes). Needs the ground model, so it
  /// is skipped where the raised check is. 0: off.
  double spike_height = 0;
  /// spike_height spares the cells within this of a raised class's cell (map units): a roof
  /// cell the class map calls road or paved stands at the roof's height.
  double spike_clearance = 0;
  double raised_height = 2.5;                    ///< map units
  double ground_window = 20;                     ///< map units
  std::vector<gaussians::RasterCamera> cameras;  ///< the training cameras
  /// The objects of these classes on the class map (geo::mapObjects cut at trim_step, slivers
  /// merged as `ortho --vectors` merges them) are trimmed to their Gaussians: the cells of an
  /// object outside the convex hull of the centres of its opaque Gaussians (those of its class,
  /// gaussian_classes, over the object: the Gaussians `ortho --object-clouds` hands out; objects
  /// of at least 20) take the most likely class of the others. A roof's translucent tails spill
  /// one to three cells over its walls onto the map; its Gaussians' centres do not. Empty: off.
  std::vector<int> trim_classes;
  double trim_step = 1.5;  ///< map units
  /// Objects of trim_classes with fewer than this many opaque Gaussians of their class over
  /// them are trimmed whole (a strip of spill between two roofs, cut off by the height steps, has
  /// a few); 0: such objects are kept (those under 20 have no hull and keep every cell).
  std::size_t trim_whole_under = 0;
  /// Per Gaussian of the model (Trainer::toCloud's order): its class as the training views
  /// render it (labelledCloud); needed by trim_classes and classes = kViews.
  std::vector<std::uint32_t> gaussian_classes;
};

/// \brief What an orthographic render gives per pixel (row-major; `covered` says which pixels
/// show a surface: accumulated alpha >= 0.5, seen by at least OrthoRenderOptions::min_views
/// training cameras; the others are nodata).
struct OrthoImages {
  int width = 0, height = 0;
  std::vector<std::uint8_t> rgb;      ///< 3 per pixel
  std::vector<std::uint8_t> covered;  ///< 1 = covered
  std::vector<std::uint8_t>
      classes;                   ///< class id, 255 = none (uncovered, or a model without classes)
  std::vector<float> elevation;  ///< map height of the rendered surface (OrthoSurface)
  /// Trainer::classCosines of the class (0 without classes); with OrthoClassSource::kViews the
  /// class's share of the blending weight.
  std::vector<float> confidence;
  std::int64_t few_views = 0;  ///< cells with a surface made nodata by min_views
  /// With OrthoRenderOptions::raised_share or pit_depth: the ground height per cell (NaN: no
  /// surface at all), each class's median height above it, the raised classes and how many cells
  /// they lost.
  std::vector<float> ground;
  std::vector<double> class_height_above_ground;
  std::vector<int> raised_classes;
  std::int64_t lowered_cells = 0;
  std::vector<int> ground_classes;  ///< geo::LowRaisedCells::ground
  std::int64_t filled_pits = 0;     ///< cells OrthoRenderOptions::pit_depth raised
  std::int64_t lowered_spikes = 0;  ///< cells OrthoRenderOptions::spike_height lowered
  double near_ground = 0;           ///< geo::LowRaisedCells::near_ground (the check's precondition)
  std::int64_t trimmed_cells = 0;   ///< cells OrthoRenderOptions::trim_classes gave another class
};

/// \brief Renders the grid in tiles of `tile` pixels; progress lines on `progress` if not null.
/// \throws sadsplat::Error for min_views > 0, min_spread_degrees > 0 or max_surface_gap > 0
/// without cameras
OrthoImages renderOrtho(const gaussians::Trainer& trainer, const OrthoGrid& grid,
                        const OrthoRenderOptions& options, std::ostream* progress = nullptr,
                        int tile = 1024);

/// \brief The scene's training cameras (OrthoRenderOptions::cameras).
std::vector<gaussians::RasterCamera> trainingCameras(const io::Scene& scene);

/// \brief "first" or "blend" as an OrthoSurface.
/// \throws sadsplat::Error naming `field` for any other text
OrthoSurface parseOrthoSurface(const std::string& text, const std::string& field);

/// \brief "views", "blend" or "first" as an OrthoClassSource.
/// \throws sadsplat::Error naming `field` for any other text
OrthoClassSource parseOrthoClassSource(const std::string& text, const std::string& field);

}  // namespace pipeline
}  // namespace sadsplat
