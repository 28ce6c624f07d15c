#pragma once
/// \file ground_model.h
/// \brief The bare ground under a surface model (a terrain model from a DSM), and the cells of a
/// class map that cannot be what they say because they lie on that ground: a "building" or
/// "tree" cell whose surface is at ground height.
///
/// The ground is a low percentile of the surface in square windows (the 25th: a window of a
/// city holds streets and yards besides its roofs, and the lowest cells of a rendered DSM are
/// pits under the true ground), the windows' values median-filtered over their 3 x 3
/// neighbours (a window a building fills takes its neighbours' ground), a window without enough
/// surface filled from the nearest ones, and interpolated bilinearly between the windows'
/// centres. It assumes what a drone survey's area is: terrain smooth over a window, objects
/// smaller than a window. No library call; plain arrays, row-major.

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sadsplat {
namespace geo {

/// \brief How the ground is estimated.
struct GroundModelOptions {
  int window_cells = 80;     ///< side of a window in cells (20 m at 0.25 m per cell)
  double percentile = 0.25;  ///< share of a window's surface cells below its ground value
  double min_covered = 0.1;  ///< share of a window's cells with a surface for it to count
};

/// \brief The ground height of every cell of a `width` x `height` grid whose surface heights are
/// `surface` where `covered` is non-zero. Every cell gets a value (windows without surface take
/// their nearest windows' ground); a grid without any surface gives NaN everywhere.
/// \throws sadsplat::Error for sizes that do not match or a window below 1 cell
std::vector<float> groundHeights(const std::vector<float>& surface,
                                 const std::vector<std::uint8_t>& covered, int width, int height,
                                 const GroundModelOptions& options = {});

/// \brief The ground under scattered points given in a frame whose third axis is up (e, n, up),
/// e.g. the centres of a model's Gaussians: the points marked in `use` are binned into square
/// cells of side `cell` over their extent, each cell's surface is its highest point (a surface
/// model of the points), groundHeights of that grid (`window` in the points' units, rounded to
/// whole cells), and each point (marked or not) takes the ground of the cell it lies in (points
/// beyond the marked ones' extent: the nearest edge cell's). All NaN when no point is marked.
/// \throws sadsplat::Error for sizes that do not match, a cell or window <= 0, or a grid of more
/// than 64 million cells
std::vector<float> groundUnderPoints(const std::vector<float>& e, const std::vector<float>& n,
                                     const std::vector<float>& up,
                                     const std::vector<std::uint8_t>& use, double cell,
                                     double window);

/// \brief The class map's cells that lie too low for their class.
struct LowRaisedCells {
  /// Per class (index = class id): the median height above the ground of its cells (NaN for a
  /// class without cells).
  std::vector<double> median_above_ground;
  std::vector<int> raised;  ///< classes whose median is at least the raised height
  /// Classes whose median is below half the raised height (roads, grass, water: not cars), the
  /// ones a low cell of a raised class can take; all classes that are not raised when none is.
  std::vector<int> ground;
  /// Cells of a raised class below share x its median (none when there is no ground class).
  std::vector<std::size_t> cells;
  /// Share of the classified cells within half the raised height of the ground. Below
  /// kMinNearGround the surface shows no ground to stand on (a DSM with pits of tens of metres, a
  /// forest): nothing is listed in `cells`.
  double near_ground = 0;
};
constexpr double kMinNearGround = 0.3;

/// \brief Finds them: a class is raised when its cells stand at a median of at least
/// `raised_height` above the ground (buildings, trees; not roads, grass, cars); a cell of a raised
/// class lower than `share` x its class's median above the ground is listed. `classes` holds
/// class ids (255: no class). A class without cells is neither raised nor ground. Below
/// `min_near_ground` (LowRaisedCells::near_ground) nothing is listed.
/// \throws sadsplat::Error for sizes that do not match, share outside (0, 1] or raised_height <= 0
LowRaisedCells findLowRaisedCells(const std::vector<std::uint8_t>& classes,
                                  const std::vector<float>& surface,
                                  const std::vector<float>& ground, int num_classes,
                                  double raised_height, double share,
                                  double min_near_ground = kMinNearGround);

/// \brief The cells of a ground class (roads, grass, water: LowRaisedCells::ground) that lie in
/// a pit (findGroundPits): a rendered DSM whose ground Gaussians are thin lets the first surface
/// fall through to the Gaussians under the ground (on a synth city orbit 17 % of the ground cells
/// lay more than 1 m below the true ground). A road is not a pit, so such a cell's height is the
/// level of the ground classes around it. Within one window of the grid's edges the level is
/// extrapolated from one side (groundHeights): on an 8 % slope it ran up to 1.1 above the ground
/// there, so a dip shallower than `depth` may be raised too (tests/geo/test_ground_model.cpp).
struct GroundOutliers {
  /// Per cell: the median height of the ground classes' cells in windows of `window_cells`, as
  /// groundHeights makes it (its 50th percentile over those cells only; NaN without any).
  std::vector<float> level;
  std::vector<std::size_t> cells;  ///< ground-class cells too far below (pits) or above `level`
};

/// \brief The pits: ground-class cells more than `depth` below the level (`classes` holds class
/// ids, 255: none; `surface` NaN: none).
/// \throws sadsplat::Error for sizes that do not match, a window below 1 cell or depth <= 0
GroundOutliers findGroundPits(const std::vector<std::uint8_t>& classes,
                              const std::vector<float>& surface,
                              const std::vector<int>& ground_classes, int width, int height,
                              int window_cells, double depth);

/// \brief The spikes: ground-class cells more than `rise` above the level of the ground classes
/// around them (the level findGroundPits takes). A cell the class map calls road or grass shows
/// the ground, so its height is the ground's: floaters over a port's quays or an orbit's
/// periphery stand metres above it, and on synth's cities the first surface keeps a roof's
/// height one to three cells beyond its walls. A misclassified roof or crown cell would be
/// lowered too: cells within `clearance_cells` (a square window) of a cell of one of
/// `raised_classes` are not listed (0: none spared), which spares the walls' halo as well.
/// \throws sadsplat::Error for sizes that do not match, a window below 1 cell, rise <= 0 or a
/// negative clearance
GroundOutliers findGroundSpikes(const std::vector<std::uint8_t>& classes,
                                const std::vector<float>& surface,
                                const std::vector<int>& ground_classes, int width, int height,
                                int window_cells, double rise,
                                const std::vector<int>& raised_classes = {},
                                int clearance_cells = 0);

}  // namespace geo
}  // namespace sadsplat
