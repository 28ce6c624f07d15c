#pragma once
/// \file counter_random.h
/// \brief Counter-based random numbers: element i of a draw is a hash of (seed, purpose,
/// iteration, i), computed on the tensor's own device. No generator state to carry, nothing
/// drawn on the CPU and copied to the GPU every iteration, the same numbers on every device and
/// after a resume.

#include <ATen/ATen.h>

#include <cstdint>

#include "sadsplat/gaussians/counter_hash.h"

namespace sadsplat {
namespace gaussians {

/// \brief splitmix64's finaliser: a well-mixed 64-bit key from any 64-bit input (the trainer's
/// seeded shuffles and generators are keyed by it too).
std::uint64_t mixBits(std::uint64_t x);

/// \brief The trainer's random streams. Each draw is keyed by (seed, purpose, iteration), so that
/// a resumed run draws what an uninterrupted one does and no two streams repeat each other. The
/// values are part of every trained model: changing one changes the results.
enum class RandomPurpose : std::uint64_t {
  kTrainingView = 1,       ///< the training view of a step (a seeded shuffle per epoch)
  kLabelledView = 2,       ///< the labelled view of a semantic step
  kDecoderInit = 3,        ///< the semantic decoder's initial weights
  kDensifySplit = 7,       ///< the samples of 3DGS's split
  kLargeSplit = 11,        ///< the samples of the split of large Gaussians
  kGateNoise = 13,         ///< the Hard Concrete gates' noise in training renders
  kDropSample = 17,        ///< the drop event's draw against P_drop
  kScaleLimitSplit = 101,  ///< the splits at the scale limit: round r draws as 101 + r (r < 8)
};

/// \brief The number a purpose keys its draws with.
inline std::uint64_t purposeKey(RandomPurpose purpose) {
  return static_cast<std::uint64_t>(purpose);
}

/// \brief A CPU generator determined by (seed, purpose, iteration): the trainer's randomness
/// drawn with LibTorch's generators.
at::Generator seededGenerator(std::uint64_t seed, RandomPurpose purpose, std::uint64_t iteration);

/// \brief The key of the draw (seed, purpose, iteration): counterUniform's element i is
/// counterUniformAt(counterKey(seed, purpose, iteration), i) (counter_hash.h).
CounterKey counterKey(std::uint64_t seed, std::uint64_t purpose, std::uint64_t iteration);

/// \brief n numbers uniform in (0, 1) (multiples of 2^-24, offset by 2^-25: never 0 or 1).
/// \param[in] options device and floating dtype of the result
at::Tensor counterUniform(std::int64_t n, std::uint64_t seed, std::uint64_t purpose,
                          std::uint64_t iteration, const at::TensorOptions& options);

}  // namespace gaussians
}  // namespace sadsplat
