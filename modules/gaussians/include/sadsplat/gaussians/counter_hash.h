#pragma once
/// \file counter_hash.h
/// \brief The arithmetic of counterUniform (counter_random.h) for one element, on the host or in
/// a CUDA kernel: kernels that need the trainer's counter-based noise draw it in place with
/// counterUniformAt(counterKey(seed, purpose, iteration), i) and get counterUniform's numbers.

#include <cstdint>

#if defined(__CUDACC__)
#define SADSPLAT_COUNTER_HD __host__ __device__ __forceinline__
#else
#define SADSPLAT_COUNTER_HD inline
#endif

namespace sadsplat {
namespace gaussians {

/// \brief The two 32-bit halves of a draw's key (counterKey in counter_random.h).
struct CounterKey {
  std::uint32_t low = 0;
  std::uint32_t high = 0;
};

/// \brief A 32-bit integer hash (xor-shift-multiply).
SADSPLAT_COUNTER_HD std::uint32_t counterHash32(std::uint32_t x) {
  x ^= x >> 16;
  x *= 0x7FEB352Du;
  x ^= x >> 15;
  x *= 0x2C1B3C6Du;
  return x ^ (x >> 16);
}

/// \brief Element i of the draw keyed by `key`: the top 24 bits of two hash rounds, centred in
/// their interval, in (0, 1).
SADSPLAT_COUNTER_HD float counterUniformAt(CounterKey key, std::int64_t i) {
  const auto index = static_cast<std::uint64_t>(i);
  std::uint32_t x = counterHash32(static_cast<std::uint32_t>(index) ^ key.low);
  x = counterHash32(x ^ (static_cast<std::uint32_t>(index >> 32) ^ key.high));
  return (static_cast<float>(x >> 8) + 0.5f) * (1.0f / 16777216.0f);
}

}  // namespace gaussians
}  // namespace sadsplat
