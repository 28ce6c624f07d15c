// Replays the committed fuzz seeds (fuzz/corpus/) and regression inputs (fuzz/regressions/) in
// the ordinary build: every input ends in success or one sadsplat::Error (the harness aborts on
// anything else), quickly (no hang).
#include <gtest/gtest.h>
#include <sys/resource.h>

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
    {"las", fuzz::fuzz_las},
    {"georeference", fuzz::fuzz_georeference},
#if SADSPLAT_HAVE_OPENCV
    {"label_png", fuzz::fuzz_label_png},
    {"transforms_json", fuzz::fuzz_transforms_json},
    {"annotations", fuzz::fuzz_annotations},
    {"photo", fuzz::fuzz_photo},
#endif
};

// fuzz/regressions/expected.tsv: "<target>/<file>\t<ok | a piece of the error message>".
std::map<std::string, std::string> expectedOutcomes() {
  std::map<std::string, std::string> out;
  std::ifstream in(fs::path(SADSPLAT_SOURCE_DIR) / "fuzz" / "regressions" / "expected.tsv");
  std::string line;
  while (std::getline(in, line)) {
    const auto tab = line.find('\t');
    if (line.empty() || line[0] == '#' || tab == std::string::npos) continue;
    out[line.substr(0, tab)] = line.substr(tab + 1);
  }
  return out;
}

TEST(FuzzCorpus, EveryCommittedInputGivesSuccessOrOneSadsplatError) {
  std::size_t inputs = 0, checked = 0;
  const std::map<std::string, std::string> outcomes = expectedOutcomes();
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
        // A regression input with a stated outcome: that outcome, from the target's last reader.
        const auto stated = outcomes.find(name + "/" + entry.path().filename().string());
        if (std::string(kind) == "regressions" && stated != outcomes.end()) {
          ++checked;
          const std::string& error = fuzz::lastError();
          if (stated->second == "ok") {
            EXPECT_EQ(error, "") << entry.path();
          } else {
            EXPECT_NE(error.find(stated->second), std::string::npos)
                << entry.path() << ": expected an error with \"" << stated->second << "\", got \""
                << error << "\"";
            EXPECT_EQ(error.find('\n'), std::string::npos) << entry.path() << ": one line";
          }
        }
        const double seconds =
            std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count();
        EXPECT_LT(seconds, 5.0) << entry.path();
        ++inputs;
      }
    }
  }
  EXPECT_GE(inputs, 20u);  // the committed files were found (27 when written)
  // expected.tsv was found and read (42 lines when written), and every stated outcome of a target
  // this build has (a build without OpenCV has no label-map, annotation or photo target) was
  // replayed.
  EXPECT_GE(outcomes.size(), 40u);
  std::size_t stated_here = 0;
  for (const auto& [file, outcome] : outcomes) {
    stated_here += kTargets.count(file.substr(0, file.find('/'))) > 0 ? 1 : 0;
  }
  EXPECT_EQ(checked, stated_here);
  // No input may take more than 1 GB (the readers bound what a header may allocate by the bytes
  // behind it): the peak resident memory of this whole process stays below that.
  struct rusage usage;
  getrusage(RUSAGE_SELF, &usage);
  EXPECT_LT(usage.ru_maxrss, 1024L * 1024L) << "peak resident memory in KiB";
}

}  // namespace
}  // namespace sadsplat
