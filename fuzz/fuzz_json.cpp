// Fuzz target: the JSON readers of a scene directory and a run: classes.json, split.json and
// train_log.jsonl.
#include "fuzz_support.h"
#include "sadsplat/io/scene.h"
#include "sadsplat/io/train_log.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  const std::string path = fuzz::inputFile("input.json");
  fuzz::writeInput(path, data, size);
  fuzz::expectOnlySadsplatErrors([&] { io::readClassesJson(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readSplitJson(path); });
  fuzz::expectOnlySadsplatErrors([&] { io::readTrainLog(path); });
  return 0;
}
