#pragma once
/// \file compact_run.h
/// \brief `sadsplat compact`: a trained run with fewer Gaussians, as a run directory that `eval`,
/// `render`, `ortho` and `tiles` take as they take the original.
///
/// The model is first taken as it renders: the drop's evaluation gate is baked into each
/// Gaussian's opacity and the gates are opened (log_alpha 10), so what follows needs no gate. Then
/// filters::compactGaussians merges it (class-aware moment matching in voxels) to at most the
/// asked count. The run's decoder, configuration and scene stay (Trainer::setGaussians), so the
/// smaller model is scored with the same classes. `model` instead takes another file's Gaussians
/// (in the run's frame, e.g. another tool's simplification of the baked model) for a side-by-side
/// score; its gates are opened likewise. `refine` trains the result further on the run's scene.

#include <cstddef>
#include <string>

namespace sadsplat {
namespace pipeline {

/// \brief What `compact` makes.
struct CompactOptions {
  std::size_t count = 0;    ///< at most this many Gaussians (0: use `ratio`)
  double ratio = 0;         ///< or this share of the model's count, in (0, 1]
  std::string model;        ///< or these Gaussians (a model file), no merge
  bool class_aware = true;  ///< merges keep classes apart
  /// then train the smaller model this many iterations more on the run's scene (its training
  /// views, the final learning rates; no densification or drop: their schedules have ended)
  int refine = 0;
};

/// \brief Writes the compacted run into `out_dir`; returns a summary line.
/// \throws sadsplat::Error on unusable options, an unreadable run or model, an unwritable output
std::string compactRun(const std::string& run_dir, const std::string& out_dir,
                       const CompactOptions& options);

}  // namespace pipeline
}  // namespace sadsplat
