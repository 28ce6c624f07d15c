// Fuzz target: the 3DGS PLY reader (ascii and binary), and the semantic PLY reader on the same
// input.
#include "fuzz_support.h"
#include "sadsplat/io/gaussian_ply.h"
#include "sadsplat/io/semantic_ply.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  const std::string path = fuzz::inputFile("input.ply");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readGaussianPly(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readSemanticPly(path); });
  return 0;
}
