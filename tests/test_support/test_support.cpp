#include "test_support/test_support.h"

#include <unistd.h>

#include <sys/wait.h>
#include <cstdio>
#include <cstdlib>
#include <cstring>
#include <fstream>
#include <random>
#include <regex>
#include <sstream>
#include <stdexcept>

namespace sadsplat {
namespace test {

TempDir::TempDir() {
  std::string pattern = (std::getenv("TMPDIR") ? std::getenv("TMPDIR") : "/tmp");
  pattern += "/sadsplat_test_XXXXXX";
  std::vector<char> buffer(pattern.begin(), pattern.end());
  buffer.push_back('\0');
  if (::mkdtemp(buffer.data()) == nullptr) throw std::runtime_error("mkdtemp failed");
  path_ = buffer.data();
}

TempDir::~TempDir() { runCommand("rm -rf '" + path_ + "'"); }

pcl::PointCloud<GaussianPoint> randomGaussians(std::size_t n, std::uint64_t seed,
                                               std::uint32_t num_classes) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<float> normal(0.f, 1.f);
  std::uniform_int_distribution<std::uint32_t> label(0, num_classes);
  pcl::PointCloud<GaussianPoint> cloud;
  cloud.resize(n);
  for (auto& p : cloud) {
    p.x = normal(rng);
    p.y = normal(rng);
    p.z = normal(rng);
    p.nx = normal(rng);
    p.ny = normal(rng);
    p.nz = normal(rng);
    for (float& v : p.f_dc) v = normal(rng);
    for (float& v : p.f_rest) v = normal(rng);
    p.opacity = normal(rng);
    for (float& v : p.scale) v = normal(rng);
    for (float& v : p.rot) v = normal(rng);
    for (float& v : p.feature) v = normal(rng);
    p.log_alpha = normal(rng);
    p.confidence = std::abs(normal(rng));
    const std::uint32_t l = label(rng);
    p.label = l == num_classes ? kUnlabelled : l;
  }
  return cloud;
}

std::string readFile(const std::string& path) {
  std::ifstream in(path, std::ios::binary);
  std::ostringstream s;
  s << in.rdbuf();
  return s.str();
}

void writeFile(const std::string& path, const std::string& bytes) {
  std::ofstream out(path, std::ios::binary | std::ios::trunc);
  out << bytes;
}

std::string copyTree(const std::string& from, const std::string& to) {
  runCommand("cp -r '" + from + "' '" + to + "'");
  return to;
}

int runCommand(const std::string& command, std::string* output) {
  FILE* pipe = ::popen((command + " 2>&1").c_str(), "r");
  if (!pipe) return -1;
  std::string text;
  char buffer[4096];
  while (std::fgets(buffer, sizeof(buffer), pipe)) text += buffer;
  const int status = ::pclose(pipe);
  if (output) *output = text;
  return WIFEXITED(status) ? WEXITSTATUS(status) : -1;
}

int runJsonIterations(const std::string& run_dir) {
  const std::string text = readFile(run_dir + "/run.json");
  std::smatch m;
  return std::regex_search(text, m, std::regex("\"iterations\": *([0-9]+)")) ? std::stoi(m[1]) : -1;
}

}  // namespace test
}  // namespace sadsplat
