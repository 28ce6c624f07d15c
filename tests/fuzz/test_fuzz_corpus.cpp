// Replays the committed fuzz seeds (fuzz/corpus/) and regression inputs (fuzz/regressions/) in
// the ordinary build: every input ends in success or one sadsplat::Error (the harness aborts on
// anything else), quickly (no hang).
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>
#include <fstream>
#include <functional>
#include <iterator>
#include <map>

#include "fuzz_targets.h"

namespace sadsplat {
namespace {

namespace fs = std::filesystem;

const std::map<std::string, std::function<void(const std::uint8_t*, std::size_t)>> kTargets = {
    {"gaussian_ply", fuzz::fuzz_gaussian_ply},
    {"pcd", fuzz::fuzz_pcd},
    {"splat_formats", fuzz::fuzz_splat_formats},
    {"scene_cache", fuzz::fuzz_scene_cache},
    {"colmap", fuzz::fuzz_colmap},
    {"json", fuzz::fuzz_json},
    {"train_config", fuzz::fuzz_train_config},
    {"checkpoint", fuzz::fuzz_checkpoint},
#if SADSPLAT_HAVE_OPENCV
    {"label_png", fuzz::fuzz_label_png},
#endif
};

TEST(FuzzCorpus, EveryCommittedInputGivesSuccessOrOneSadsplatError) {
  std::size_t inputs = 0;
  for (const char* kind : {"corpus", "regressions"}) {
    const fs::path root = fs::path(SADSPLAT_SOURCE_DIR) / "fuzz" / kind;
    for (const auto& [name, target] : kTargets) {
      if (!fs::is_directory(root / name)) continue;
      for (const auto& entry : fs::directory_iterator(root / name)) {
        std::ifstream in(entry.path(), std::ios::binary);
        const std::string bytes((std::istreambuf_iterator<char>(in)),
                                std::istreambuf_iterator<char>());
        const auto start = std::chrono::steady_clock::now();
        target(reinterpret_cast<const std::uint8_t*>(bytes.data()), bytes.size());
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_LT(seconds, 5.0) << entry.path();
        ++inputs;
      }
    }
  }
  EXPECT_GE(inputs, 20u);  // the committed files were found (27 when written)
}

}  // namespace
}  // namespace sadsplat
