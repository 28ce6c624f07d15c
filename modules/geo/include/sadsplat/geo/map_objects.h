#pragma once
/// \file map_objects.h
/// \brief Objects on a class map: the regions of a class, split where the surface model steps.
/// Two buildings whose roofs spill a cell or two over the gap between them are one region of
/// the class map, but their roofs stand at different heights, and the cells that bridge them lie
/// at a third (the ground's, or a wall's); so the region is cut wherever neighbouring cells'
/// heights differ by more than a step, as GIS building extraction segments a normalised DSM.
/// The slivers a cut leaves along walls (cells between a roof's height and the ground's) are then
/// merged into the object they border most, as GDAL's sieve filter merges small regions.

#include <array>
#include <cstddef>
#include <cstdint>
#include <vector>

namespace sadsplat {
namespace geo {

struct MapObjectOptions {
  /// Metres: 8-neighbouring cells of the mask belong to one object when their heights differ by
  /// at most this (0: any neighbours do, the plain connected regions). 1.5 m was the best of 3,
  /// 2, 1.5, 1 and 0.5 for building objects on the benchmark (docs/measurements/cloud_3d).
  double max_step = 1.5;
  /// Objects under this many cells merge into the neighbouring object they share the most cell
  /// borders with (0: none merge); one with no neighbour stays as it is.
  std::size_t min_cells = 0;
};

/// \brief Labels the cells of `mask` (row-major, `width` x `height`, non-zero = in) with objects
/// 1..n (0 outside the mask), numbered in row-major order of their first cell: 8-connected,
/// neighbours joined when |heights[a] - heights[b]| <= max_step (both non-finite also join; a
/// finite and a non-finite height never do). `heights` may be empty when max_step is 0.
/// \throws sadsplat::Error when the sizes disagree, max_step < 0 or heights are missing
std::vector<int> mapObjects(const std::vector<std::uint8_t>& mask,
                            const std::vector<float>& heights, int width, int height,
                            const MapObjectOptions& options);

/// \brief The cells of labelled objects whose centre lies outside their object's convex
/// polygon: `labels` as mapObjects gives them (`width` cells a row), `hulls[k - 1]` object k's
/// convex polygon in cell units (x right from the grid's left edge, y down from its top: cell
/// (i, j)'s centre is (i + 0.5, j + 0.5); either orientation); an object whose polygon has fewer
/// than three corners keeps every cell. Ascending.
/// \throws sadsplat::Error when a label has no polygon
std::vector<std::size_t> cellsOutsideHulls(
    const std::vector<int>& labels, int width,
    const std::vector<std::vector<std::array<double, 2>>>& hulls);

/// \brief Gives each of `cells` the class most of the cells within `radius` cells around it
/// have (a square window), counting only covered cells of an `allowed` class (allowed[class] !=
/// 0) that are not among `cells`; ties go to the lower class id. Returns the cells with no such
/// cell around them, unchanged. `classes`, `covered`: row-major, `width` x `height`.
std::vector<std::size_t> takeClassAround(std::vector<std::uint8_t>& classes,
                                         const std::vector<std::uint8_t>& covered, int width,
                                         int height, const std::vector<std::size_t>& cells,
                                         const std::vector<std::uint8_t>& allowed, int radius);

}  // namespace geo
}  // namespace sadsplat
