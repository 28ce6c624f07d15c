// libFuzzer program for fuzz::fuzz_las (fuzz_targets.h).
#include "fuzz_targets.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  sadsplat::fuzz::fuzz_las(data, size);
  return 0;
}
