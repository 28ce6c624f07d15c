// Fuzz target: COLMAP models, text and binary. The input is split at the first two bytes 0xff
// 0xfe into cameras / images / points3D; its first byte chooses text (even) or binary (odd).
#include <algorithm>
#include <vector>

#include "fuzz_support.h"
#include "sadsplat/io/colmap.h"

extern "C" int LLVMFuzzerTestOneInput(const std::uint8_t* data, std::size_t size) {
  using namespace sadsplat;
  if (size < 1) return 0;
  const bool binary = data[0] & 1;
  std::vector<std::pair<const std::uint8_t*, std::size_t>> parts;
  const std::uint8_t* begin = data + 1;
  const std::uint8_t* end = data + size;
  for (int k = 0; k < 2; ++k) {
    const std::uint8_t sep[2] = {0xff, 0xfe};
    const std::uint8_t* at = std::search(begin, end, sep, sep + 2);
    parts.emplace_back(begin, static_cast<std::size_t>(at - begin));
    begin = at == end ? end : at + 2;
  }
  parts.emplace_back(begin, static_cast<std::size_t>(end - begin));
  const std::string dir = fuzz::inputFile(binary ? "bin" : "text");
  std::system(("rm -rf " + dir + " && mkdir -p " + dir).c_str());
  const char* names[3] = {"cameras", "images", "points3D"};
  for (int k = 0; k < 3; ++k) {
    fuzz::writeInput(dir + "/" + names[k] + (binary ? ".bin" : ".txt"), parts[k].first,
                     parts[k].second);
  }
  fuzz::expectOnlySadsplatErrors([&] { io::readColmapModel(dir); });
  return 0;
}
