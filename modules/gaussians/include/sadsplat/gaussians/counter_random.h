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

/// \brief The key of the draw (seed, purpose, iteration): counterUniform's element i is
/// counterUniformAt(counterKey(seed, purpose, iteration), i) (counter_hash.h).
CounterKey counterKey(std::uint64_t seed, std::uint64_t purpose, std::uint64_t iteration);

/// \brief n numbers uniform in (0, 1) (multiples of 2^-24, offset by 2^-25: never 0 or 1).
/// \param[in] options device and floating dtype of the result
at::Tensor counterUniform(std::int64_t n, std::uint64_t seed, std::uint64_t purpose,
                          std::uint64_t iteration, const at::TensorOptions& options);

}  // namespace gaussians
}  // namespace sadsplat
