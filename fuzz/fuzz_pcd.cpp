// Fuzz target: the PCD codec (ascii, binary, binary_compressed), as Gaussians and as a semantic
// cloud.
#include "fuzz_support.h"
#include "sadsplat/io/pcd.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  const std::string path = fuzz::inputFile("input.pcd");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::loadGaussianPcd(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::loadSemanticPcd(path); });
  return 0;
}
