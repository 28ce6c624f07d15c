#pragma once
// Helpers shared by the test suites: temporary directories, random Gaussians, file bytes.

#include <pcl/point_cloud.h>

#include <cstdint>
#include <string>

#include "sadsplat/common/gaussian_point.h"

namespace sadsplat {
namespace test {

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

/// Runs a shell command, returns its exit status; its stdout+stderr go to *output if given.
int runCommand(const std::string& command, std::string* output = nullptr);

}  // namespace test
}  // namespace sadsplat
