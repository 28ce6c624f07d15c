// `sadsplat info` (io::describeFile) and atomic outputs on the odd inputs a mutation pass found:
// FIFOs, directories named like files, output names near NAME_MAX, the web formats' headers.
#include <gtest/gtest.h>

#include <chrono>
#include <filesystem>

#include "sadsplat/common/error.h"
#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/cloud_files.h"
#include "sadsplat/io/file_info.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/georeference.h"
#include "sadsplat/io/splat_formats.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

std::string describeError(const std::string& path) {
  try {
    io::describeFile(path);
  } catch (const Error& e) {
    return e.what();
  }
  return "";
}

TEST(FileInfo, AFifoIsAnErrorNotABlockingRead) {
  test::TempDir dir;
  for (const char* name : {"pipe.ply", "pipe.cache", "pipe"}) {
    ASSERT_EQ(test::runCommand("mkfifo " + dir.file(name)), 0);
    const auto start = std::chrono::steady_clock::now();
    EXPECT_NE(describeError(dir.file(name)).find("a regular file"), std::string::npos) << name;
    EXPECT_LT(std::chrono::duration<double>(std::chrono::steady_clock::now() - start).count(), 2);
  }
}

TEST(FileInfo, ADirectoryNamedLikeACloudIsBlamedItself) {
  test::TempDir dir;
  io::makeDirectory(dir.file("model.ply"));
  const std::string message = describeError(dir.file("model.ply"));
  EXPECT_EQ(message, dir.file("model.ply") + ": file: expected a .ply file, got a directory");
}

TEST(FileInfo, SpzShowsVersionDegreeAndFlags) {
  test::TempDir dir;
  io::SpzWriteOptions options;
  options.version = 4;
  options.antialiased = true;
  options.sh_degree = 2;
  io::writeSpz(dir.file("m.spz"), test::randomGaussians(5, 3), options);
  const std::string text = io::describeFile(dir.file("m.spz"));
  EXPECT_NE(text.find("SPZ version 4"), std::string::npos) << text;
  EXPECT_NE(text.find("SH degree: 2"), std::string::npos) << text;
  EXPECT_NE(text.find("antialiased: yes"), std::string::npos) << text;
  EXPECT_NE(text.find("gaussians: 5"), std::string::npos) << text;
}

// A run's frame as info states it: fitted to control points with the check points' RMSE, or a
// doubtful GPS frame said loudly, its file-borne text escaped.
TEST(FileInfo, TheGeoreferenceSaysItsSourceChecksAndDoubts) {
  test::TempDir dir;
  const std::string run = dir.file("run");
  io::makeDirectory(run);
  test::writeFile(run + "/run.json", "{}");
  std::filesystem::copy_file(
      std::string(SADSPLAT_TEST_DATA_DIR) + "/interop/splat_transform_compressed_decoded.ply",
      run + "/model.ply");
  io::Georeference g;
  g.origin = {47.3769, 8.5417, 420};
  g.epsg_utm = 32632;
  g.up_source = "ground control points";
  g.control_points = 10;
  g.check_points = 2;
  g.check_rmse_horizontal = 0.109;
  g.check_rmse_vertical = 0.659;
  test::writeFile(run + "/georeference.json", io::georeferenceToJson(g));
  std::string text = io::describeFile(run);
  EXPECT_NE(text.find("fitted to 10 ground control points"), std::string::npos) << text;
  EXPECT_NE(text.find("2 check points: RMSE horizontal 0.109 m, vertical 0.659 m"),
            std::string::npos)
      << text;
  EXPECT_EQ(text.find("DOUBTFUL"), std::string::npos) << text;
  g.control_points = g.check_points = 0;
  g.up_source = "nadir views";
  g.doubts = {"only 3 of 40 photos' GPS agree \x1b[2J"};
  test::writeFile(run + "/georeference.json", io::georeferenceToJson(g));
  text = io::describeFile(run);
  EXPECT_NE(text.find("DOUBTFUL: only 3 of 40"), std::string::npos) << text;
  EXPECT_EQ(text.find('\x1b'), std::string::npos) << text;
  EXPECT_NE(text.find("\\x1B[2J"), std::string::npos) << text;
}

// The decoded reference PLY of splat-transform keeps 255 alphas as +inf: info counts the clamps.
TEST(FileInfo, CountsClampedOpacities) {
  const std::string path =
      std::string(SADSPLAT_TEST_DATA_DIR) + "/interop/splat_transform_compressed_decoded.ply";
  const std::string text = io::describeFile(path);
  EXPECT_NE(text.find("opacities clamped: "), std::string::npos) << text;
}

// "<name>.tmp-<pid>" would pass NAME_MAX for names of 246..255 bytes: they are written anyway.
TEST(AtomicFile, OutputNamesUpToNameMaxAreWritten) {
  test::TempDir dir;
  for (std::size_t length : {200u, 246u, 251u, 255u}) {
    const std::string name = std::string(length - 4, 'm') + ".ply";
    io::writeFileAtomically(dir.file(name), [](std::ostream& out) { out << "x"; });
    EXPECT_EQ(test::readFile(dir.file(name)), "x") << length;
  }
  std::string listing;
  test::runCommand("ls -A " + dir.file(""), &listing);
  EXPECT_EQ(listing.find("tmp"), std::string::npos) << listing;  // no temporary file left
}

}  // namespace
}  // namespace sadsplat
