#pragma once
/// \file block_partition.h
/// \brief A scene cut into blocks on its ground plane, for training a survey block by block
/// (VastGaussian / CityGaussian style): a grid of cells over the sparse points, each cell grown
/// by an overlap into the block a training run sees, and the training views of each block chosen
/// by what they see.
///
/// The ground plane is the map frame's (geo::sceneUp: ENU for a georeferenced scene, otherwise
/// minus the cameras' mean viewing direction). The grid's inner edges are even between the 1st
/// and 99th percentiles of the sparse points' ground coordinates; the outer cells reach to
/// infinity, so every point of space lies in exactly one cell (half-open intervals), and a merge
/// that keeps each block's Gaussians inside its own cell keeps every Gaussian once.
///
/// A training view belongs to a block when, of the sparse points in front of it that project
/// into its image, at least `view_share` lie in the block's grown cell (a labelled view: at least
/// `labelled_view_share`, since labels are scarce); a view that reaches that share nowhere
/// belongs to the block with the largest share, so that no training view is left out. The
/// points have no occlusion test (the scene keeps no tracks): a view sees a point when it
/// projects into its image.

#include <array>
#include <limits>
#include <string>
#include <vector>

#include "sadsplat/geo/map_frame.h"
#include "sadsplat/io/scene.h"

namespace sadsplat {
namespace geo {

/// \brief How to cut a scene.
struct BlockOptions {
  int blocks = 4;                     ///< cells of the grid (rows x columns = blocks)
  double overlap = 0.25;              ///< a block's cell grown by this share of the cell's size
  double view_share = 0.25;           ///< share of a view's points in a block to train on it
  double labelled_view_share = 0.05;  ///< the same for a labelled view
  /// \throws sadsplat::Error naming `origin` and the field when a value is out of range
  void check(const std::string& origin) const;
};

/// \brief A rectangle of the ground plane, [e0, e1) x [n0, n1); infinite bounds allowed.
struct GroundRect {
  double e0 = -std::numeric_limits<double>::infinity();
  double e1 = std::numeric_limits<double>::infinity();
  double n0 = -std::numeric_limits<double>::infinity();
  double n1 = std::numeric_limits<double>::infinity();
  bool contains(double e, double n) const { return e >= e0 && e < e1 && n >= n0 && n < n1; }
};

/// \brief One block: its cell, the grown cell its training sees, its views and points.
struct Block {
  int index = 0;  ///< row * columns + column
  int row = 0, column = 0;
  GroundRect cell;                ///< the Gaussians the merge keeps from this block
  GroundRect grown;               ///< the cell grown by the overlap: the points it starts from
  std::vector<int> views;         ///< indices into scene.views (training views), ascending
  std::vector<int> points;        ///< indices into scene.points inside `grown`
  std::vector<double> shares;     ///< per entry of `views`: the share of its points in `grown`
  int labelledViews(const io::Scene& scene) const;
};

/// \brief The grid and its blocks.
struct BlockPartition {
  MapFrame ground;  ///< scene -> (e, n, up): a local map frame whose z is the scene's up
  int rows = 1, columns = 1;
  std::vector<double> e_edges;  ///< columns + 1 edges (the outer two infinite)
  std::vector<double> n_edges;  ///< rows + 1 edges (the outer two infinite)
  std::vector<Block> blocks;    ///< rows x columns, row-major
  /// Per scene view (training and test): the share of the sparse points it sees that lie in each
  /// block's cell (empty: it sees none). A view whose largest share is well below 1 straddles a
  /// border: its render draws Gaussians of several blocks.
  std::vector<std::vector<double>> view_cell_shares;

  /// \brief The block whose cell holds a scene point.
  int blockOf(const std::array<double, 3>& scene_point) const;
  /// \brief The block whose cell holds the ground-plane point (e, n).
  int blockAt(double e, double n) const;
  /// \brief The same for many points (x, y, z interleaved), one index per point.
  std::vector<int> blocksOf(const float* xyz, std::size_t count) const;
  /// \brief JSON text: the grid; per block its cell, grown cell, views (names and shares) and
  /// point count; per scene view its cell shares (blocks.json of a block run).
  std::string toJson(const io::Scene& scene) const;
};

/// \brief The grid shape for `blocks` cells over a ground extent of width x height: the
/// factorisation rows x columns = blocks whose cells are closest to square.
std::array<int, 2> gridShape(int blocks, double width, double height);

/// \brief Cuts the scene (see the file comment).
/// \throws sadsplat::Error naming `origin` when the scene has no sparse points or no training
/// view, or the options are out of range
BlockPartition partitionScene(const io::Scene& scene, const BlockOptions& options,
                              const std::string& origin);

/// \brief The scene a block trains on: its views (with their images, labels and pseudo-labels)
/// and its points, the scene's classes and georeference.
io::Scene blockScene(const io::Scene& scene, const Block& block);

}  // namespace geo
}  // namespace sadsplat
