// Fuzz target: the .splat and .spz readers. Inputs that start with gzip's magic go to .spz;
// the others are also tried as .splat.
#include "fuzz_support.h"
#include "sadsplat/io/splat_formats.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  const std::string spz = fuzz::inputFile("input.spz");
  fuzz::writeInput(spz, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readSpz(spz); });
  const std::string splat = fuzz::inputFile("input.splat");
  fuzz::writeInput(splat, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readSplat(splat); });
  return 0;
}
