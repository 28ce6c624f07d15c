#include "sadsplat/gaussians/counter_random.h"

#include <ATen/CPUGeneratorImpl.h>

namespace sadsplat {
namespace gaussians {

std::uint64_t mixBits(std::uint64_t x) {
  x += 0x9E3779B97F4A7C15ull;
  x = (x ^ (x >> 30)) * 0xBF58476D1CE4E5B9ull;
  x = (x ^ (x >> 27)) * 0x94D049BB133111EBull;
  return x ^ (x >> 31);
}

at::Generator seededGenerator(std::uint64_t seed, RandomPurpose purpose, std::uint64_t iteration) {
  return at::detail::createCPUGenerator(
      mixBits(seed ^ mixBits(purposeKey(purpose) ^ mixBits(iteration))));
}

namespace {

// A 32-bit integer hash as int64 tensor operations that never overflow (shifts of
// non-negative values are logical): values stay below
// 2^32 and the multipliers below 2^31 (so products stay below 2^63).
at::Tensor hash32(at::Tensor x) {
  const std::int64_t mask = 0xFFFFFFFF;
  x = at::bitwise_xor(x, at::__rshift__(x, std::int64_t{16}));
  x = at::bitwise_and(x * std::int64_t{0x7FEB352D}, mask);
  x = at::bitwise_xor(x, at::__rshift__(x, std::int64_t{15}));
  x = at::bitwise_and(x * std::int64_t{0x2C1B3C6D}, mask);
  return at::bitwise_xor(x, at::__rshift__(x, std::int64_t{16}));
}

}  // namespace

CounterKey counterKey(std::uint64_t seed, std::uint64_t purpose, std::uint64_t iteration) {
  const std::uint64_t key = mixBits(seed ^ mixBits(purpose ^ mixBits(iteration)));
  CounterKey k;
  k.low = static_cast<std::uint32_t>(key & 0xFFFFFFFFull);
  k.high = static_cast<std::uint32_t>(key >> 32);
  return k;
}

at::Tensor counterUniform(std::int64_t n, std::uint64_t seed, std::uint64_t purpose,
                          std::uint64_t iteration, const at::TensorOptions& options) {
  const CounterKey key = counterKey(seed, purpose, iteration);
  const std::int64_t low = key.low, high = key.high;
  const at::Tensor index = at::arange(n, options.dtype(at::kLong));
  // Two rounds keyed by both halves of the key; the index's high bits enter the second round.
  at::Tensor x = hash32(at::bitwise_xor(at::bitwise_and(index, std::int64_t{0xFFFFFFFF}), low));
  x = hash32(at::bitwise_xor(x, at::bitwise_xor(at::__rshift__(index, std::int64_t{32}), high)));
  // The top 24 bits, centred in their interval.
  return (at::__rshift__(x, std::int64_t{8}).to(options.dtype()) + 0.5) * (1.0 / (1 << 24));
}

}  // namespace gaussians
}  // namespace sadsplat
