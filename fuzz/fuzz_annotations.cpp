// libFuzzer program for fuzz::fuzz_annotations (fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sadsplat::fuzz::fuzz_annotations(data, size);
  return 0;
}
