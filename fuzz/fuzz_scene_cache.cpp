// Fuzz target: the scene cache, structure-aware: the input is the payload (chunks, including
// the pseudo-label chunk), given a valid header with its size and checksum, so that the fuzzer
// reaches the chunk parsers instead of stopping at the checksum.
#include <cstring>
#include <vector>

#include "fuzz_support.h"
#include "sadsplat/io/scene_cache.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  std::vector<std::uint8_t> file(32 + size);
  std::memcpy(file.data(), "SADSCENE", 8);
  // The version is taken from the committed fixture's header by the seed corpus's first file;
  // it is read here from the build's own writer: 4 bytes after the magic.
  static const std::uint32_t version = [] {
    io::Scene empty;
    empty.classes.push_back({"a", {1, 2, 3}, "a"});
    const std::string probe = fuzz::inputFile("probe.cache");
    io::writeSceneCache(probe, empty);
    std::ifstream in(probe, std::ios::binary);
    char head[12];
    in.read(head, 12);
    std::uint32_t v;
    std::memcpy(&v, head + 8, 4);
    return v;
  }();
  const std::uint32_t flags = 0;
  const std::uint64_t payload = size;
  const std::uint64_t checksum = io::fnv1a64(data, size);
  std::memcpy(file.data() + 8, &version, 4);
  std::memcpy(file.data() + 12, &flags, 4);
  std::memcpy(file.data() + 16, &payload, 8);
  std::memcpy(file.data() + 24, &checksum, 8);
  if (size > 0) std::memcpy(file.data() + 32, data, size);
  const std::string path = fuzz::inputFile("input.cache");
  fuzz::writeInput(path, file.data(), file.size());
  fuzz::expectOnlySadsplatErrors([&] { io::readSceneCache(path); });
  return 0;
}
