#pragma once
/// \file pseudo_label_run.h
/// \brief The job behind `sadsplat pseudo-labels`: load a scene, run a backend, write the scene
/// cache with the pseudo-labels, and optionally a quality report (report.json, report.txt and,
/// with OpenCV, overlays/*.png).

#include <ostream>
#include <string>

#include "sadsplat/pseudo_labels/generator.h"

namespace sadsplat {
namespace pipeline {

/// \brief Options of a pseudo-label run.
struct PseudoLabelRunOptions {
  std::string scene;                ///< scene directory or scene cache
  std::string out;                  ///< scene cache to write (default: the input cache, replaced)
  double scale = 0.5;               ///< import scale for scene directories
  std::string backend = "builtin";  ///< builtin | torchscript
  std::string sam_model;   ///< torchscript: SAM export (see scripts/export_foundation_models.py)
  std::string clip_model;  ///< torchscript: CLIP-family export
  pseudo_labels::BuiltinOptions builtin;
  pseudo_labels::PseudoLabelOptions filter;
  std::string report_dir;  ///< write the quality report here (empty: none)
  std::ostream* progress = nullptr;
};

/// \brief Runs the job; returns the report text (empty without report_dir).
/// \throws sadsplat::Error on bad input
std::string pseudoLabelRun(const PseudoLabelRunOptions& options);

}  // namespace pipeline
}  // namespace sadsplat
