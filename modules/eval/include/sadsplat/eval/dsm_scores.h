#pragma once
/// \file dsm_scores.h
/// \brief A surface model (DSM) scored against the true heights on the same grid: RMSE, median
/// absolute error and NMAD (1.4826 x the median absolute deviation from the median error: the
/// robust spread of Hoehle & Hoehle 2009, which a few wrong cells do not dominate), over every
/// scored cell and over the cells away from the truth's height steps. At a wall the true height
/// jumps by the building's height within one cell, so an edge misplaced by a fraction of a cell
/// costs metres in the cells beside it: on a synth city orbit those cells were a tenth of the
/// roof cells and half of the roofs' squared error (docs/measurements/cloud_3d).

#include <cstddef>
#include <cstdint>
#include <vector>

namespace sadsplat {
namespace eval {

/// \brief The errors (model minus truth, metres) of one set of cells.
struct HeightErrors {
  std::size_t cells = 0;
  double rmse_m = 0, median_abs_m = 0, nmad_m = 0;
  /// The cells that are not at a height step (DsmScoreOptions::step_m) and their RMSE.
  std::size_t off_step_cells = 0;
  double off_step_rmse_m = 0;
};

struct DsmScoreOptions {
  /// A cell is at a height step when the true heights of its 3 x 3 neighbourhood (those known)
  /// span more than this (metres): the cells on both sides of a wall, a tree's rim.
  double step_m = 2.0;
};

struct DsmScores {
  HeightErrors all;
  std::vector<HeightErrors> per_class;  ///< by the true class of the cell
};

/// \brief Scores `model` against `truth` (both [height x width], row-major metres) over the
/// cells where `scored` is non-zero and both heights are finite, per true class from `classes`
/// (values >= num_classes are not scored).
/// \throws sadsplat::Error when the sizes disagree
DsmScores scoreDsm(const std::vector<float>& model, const std::vector<float>& truth,
                   const std::vector<std::uint8_t>& classes,
                   const std::vector<std::uint8_t>& scored, int width, int height, int num_classes,
                   const DsmScoreOptions& options = {});

/// \brief The height-step cells of `truth` ([height x width]; DsmScoreOptions::step_m).
std::vector<std::uint8_t> heightStepCells(const std::vector<float>& truth, int width, int height,
                                          double step_m);

}  // namespace eval
}  // namespace sadsplat
