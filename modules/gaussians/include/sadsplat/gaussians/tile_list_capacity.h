#pragma once
/// \file tile_list_capacity.h
/// \brief How a CUDA render sizes its list of (Gaussian, tile) pairs without waiting for the GPU.
///
/// The rasterizer sorts one entry per (Gaussian, tile) pair. The GPU counts the pairs; sizing the
/// list to that count makes the host wait for the GPU's queue once per render, after which the
/// GPU idles while the host issues the render's next operations. With a TileListCapacity the
/// render takes a list of `capacity()` entries instead (unused entries sort last and belong to
/// no tile: the image and gradients are bit-identical to an exactly sized list's) and leaves the
/// count on its way to the host. renderedAll() reads the counts later — in training after the
/// backward pass, when the GPU has long passed them — and says whether every render had room.
/// A render whose list was too short missed pairs: the caller renders it again (the trainer does
/// so without a capacity). The capacity follows the counts: `margin` times the largest count of the
/// last check, shrinking by at most 2 % per check.

#include <cstdint>
#include <memory>

namespace sadsplat {
namespace gaussians {

class TileListCapacity {
 public:
  /// \param margin room over the largest recent count, >= 1
  /// \throws sadsplat::Error when margin < 1
  explicit TileListCapacity(double margin = 1.25);
  ~TileListCapacity();
  TileListCapacity(const TileListCapacity&) = delete;
  TileListCapacity& operator=(const TileListCapacity&) = delete;

  /// \brief Whether every render that used this since the last call had room for all its pairs.
  /// Waits for the GPU only until those renders' counts are known. false: at least one render
  /// missed pairs, so its images and gradients are wrong — render it again; the capacity has
  /// grown to fit the counts.
  bool renderedAll();

  /// \brief Entries the next render's list gets; 0 until a count is known (the render then
  /// counts its pairs, waiting, and reports them with counted()).
  std::int64_t capacity() const;

  /// \brief For the CUDA backend: a render with a list of capacity() entries is being queued.
  /// Returns where its count goes (pinned host memory) and the cudaEvent_t to record after the
  /// count's copy is queued.
  struct Slot {
    std::int64_t* count = nullptr;
    void* event = nullptr;
  };
  Slot reserve();
  /// \brief For the CUDA backend: a render counted its pairs exactly (it waited).
  void counted(std::int64_t pairs);

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

}  // namespace gaussians
}  // namespace sadsplat
