#pragma once
/// \file splat_frames.h
/// \brief Frames of a model rendered by sadsplat's own rasterizer, for the viewer's splat mode
/// (`sadsplat view`): what the model looks like, not discs.

#include <memory>
#include <string>

#include "sadsplat/io/splat_frame.h"

namespace sadsplat {
namespace pipeline {

/// \brief Renders frames of one model.
///
/// A run directory (run.json and checkpoint.bin) is opened as `render` and `eval` open it: the
/// same Gaussians, drop gate and class decoder, so that a frame through a scene camera is the
/// run's render of that camera, and classes are decoded per pixel. Any other Gaussian model (a
/// .ply / .pcd, or a folder with model.ply) has no decoder: its per-pixel class is the argmax of
/// the Gaussians' labels blended like colours (-2 where only unlabelled Gaussians are seen).
class SplatFrames {
 public:
  using Ptr = std::shared_ptr<SplatFrames>;

  /// \param[in] path run directory, model file or folder holding model.ply
  /// \param[in] device "cpu" or "cuda"
  /// \throws sadsplat::Error naming the path when it holds no readable model
  explicit SplatFrames(const std::string& path, const std::string& device = "cpu");
  ~SplatFrames();

  /// \brief One frame as `request` asks (its camera's size).
  io::SplatFrame render(const io::FrameRequest& request) const;
  /// \brief Whether classes come from a decoder (a run) rather than the Gaussians' labels.
  bool decodesClasses() const;

 private:
  struct State;
  std::unique_ptr<State> state_;
};

}  // namespace pipeline
}  // namespace sadsplat
