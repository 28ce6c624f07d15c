#pragma once
// Helpers shared by the test suites: temporary directories, random Gaussians, file bytes.

#include <pcl/point_cloud.h>

#include <cstdint>
#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace test {

// Every suite is compiled with SADSPLAT_TEST_DATA_DIR and SADSPLAT_CLI (tests/CMakeLists.txt).
/// The CLI under test.
inline const std::string kCli = SADSPLAT_CLI;
/// The small fixture scene (data/tiny_scene) and its scene cache.
inline const std::string kTinyScene = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene";
inline const std::string kTinySceneCache = kTinyScene + ".cache";

/// A fresh, empty directory under the system temp dir, removed at destruction.
class TempDir {
 public:
  TempDir();
  ~TempDir();
  TempDir(const TempDir&) = delete;
  TempDir& operator=(const TempDir&) = delete;
  const std::string& path() const { return path_; }
  std::string file(const std::string& name) const { return path_ + "/" + name; }

 private:
  std::string path_;
};

/// `n` Gaussians with every field random (seeded), labels in [0, num_classes) or unlabelled.
pcl::PointCloud<GaussianPoint> randomGaussians(std::size_t n, std::uint64_t seed,
                                               std::uint32_t num_classes = 5);

std::string readFile(const std::string& path);
void writeFile(const std::string& path, const std::string& bytes);

/// Copies a directory tree (cp -r); returns the destination.
std::string copyTree(const std::string& from, const std::string& to);

/// The iteration count a training run's RUN/run.json records (-1 when it has none).
int runJsonIterations(const std::string& run_dir);

/// Runs a shell command, returns its exit status; its stdout+stderr go to *output if given.
int runCommand(const std::string& command, std::string* output = nullptr);

}  // namespace test
}  // namespace sadsplat
