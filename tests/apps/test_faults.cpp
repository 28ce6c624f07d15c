// Faults that lose nothing: a diverged training, SIGINT, kill -9 and a full or read-only disk.
// Each runs the CLI as a user would and checks what is left on disk.
#include <gtest/gtest.h>

#include <cstdio>
#include <regex>

#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/gaussian_ply.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

using test::kCli;
using test::kTinySceneCache;
using test::runJsonIterations;

// A learning rate that overflows the decoder makes the loss NaN: the run stops with an error
// naming the iteration, and the last checkpoint (and its run.json) stay as they were written.
TEST(Faults, DivergedTrainingStopsAndKeepsTheLastCheckpoint) {
  test::TempDir dir;
  test::writeFile(dir.file("cfg.json"), "{\"lr_decoder\": 1e38, \"checkpoint_interval\": 4}");
  std::string out;
  EXPECT_EQ(test::runCommand(kCli + " train " + kTinySceneCache + " --iterations 40 --config " +
                                 dir.file("cfg.json") + " --out " + dir.file("run"),
                             &out),
            1);
  std::smatch m;
  ASSERT_TRUE(std::regex_search(out, m,
                                std::regex("training at iteration (\\d+): expected a finite loss, "
                                           "got NaN \\(diverged; checkpoint.bin keeps iteration "
                                           "(\\d+)")))
      << out;
  const int failed = std::stoi(m[1]), kept = std::stoi(m[2]);
  EXPECT_GT(failed, kept);
  EXPECT_EQ(kept % 4, 0);
  EXPECT_EQ(runJsonIterations(dir.file("run")), kept);
  EXPECT_TRUE(io::isRegularFile(dir.file("run/checkpoint.bin")));
  EXPECT_FALSE(io::pathExists(dir.file("run/model.ply")));  // no model from a diverged state
}

// SIGINT: a checkpoint of the iteration reached, exit status 130, and --resume goes on from it.
TEST(Faults, SigintWritesACheckpointAndResumes) {
  test::TempDir dir;
  const std::string run = dir.file("run");
  std::string out;
  const int rc = test::runCommand(
      "(" + kCli + " train " + kTinySceneCache + " --iterations 1000000 --out " + run +
          " & pid=$!; for i in $(seq 100); do sleep 0.1; grep -q '\"device\"' " + run +
          "/config.json 2>/dev/null && break; done; sleep 0.5; kill -INT $pid; wait $pid)",
      &out);
  EXPECT_EQ(rc, 130) << out;
  EXPECT_NE(out.find("sadsplat: interrupted:"), std::string::npos) << out;
  const int reached = runJsonIterations(run);
  ASSERT_GT(reached, 0) << out;
  EXPECT_TRUE(io::isRegularFile(run + "/checkpoint.bin"));
  ASSERT_EQ(test::runCommand(kCli + " train " + kTinySceneCache + " --iterations " +
                                 std::to_string(reached + 10) + " --resume --out " + run,
                             &out),
            0)
      << out;
  EXPECT_EQ(runJsonIterations(run), reached + 10);
}

// kill -9 (the process kills itself right after an iteration, before its checkpoint) and
// --resume give the model of an uninterrupted run, bit for bit: once at a densification
// iteration (20: densification every 10 from 10 to 30), once after the last densification.
TEST(Faults, KillNineThenResumeIsBitIdentical) {
  test::TempDir dir;
  test::writeFile(dir.file("cfg.json"),
                  "{\"checkpoint_interval\": 10, \"densify_from\": 10, \"densify_interval\": 10, "
                  "\"densify_until\": 30}");
  const std::string train =
      kCli + " train " + kTinySceneCache + " --iterations 50 --config " + dir.file("cfg.json") + " --out ";
  std::string out;
  ASSERT_EQ(test::runCommand(train + dir.file("whole"), &out), 0) << out;
  const std::string want = test::readFile(dir.file("whole/model.ply"));
  for (int kill_at : {20, 35}) {
    const std::string run = dir.file("killed_" + std::to_string(kill_at));
    const int rc = test::runCommand(
        "SADSPLAT_FAULT_KILL_AT_ITERATION=" + std::to_string(kill_at) + " " + train + run, &out);
    EXPECT_NE(rc, 0) << out;  // killed by SIGKILL
    EXPECT_FALSE(io::pathExists(run + "/model.ply"));
    EXPECT_EQ(runJsonIterations(run),
              kill_at / 10 * 10 == kill_at ? kill_at - 10 : kill_at / 10 * 10);
    ASSERT_EQ(test::runCommand(train + run + " --resume", &out), 0) << out;
    EXPECT_TRUE(test::readFile(run + "/model.ply") == want) << "kill at " << kill_at;
  }
}

// A full disk and a read-only one: a clear error, the previous file intact, no temporary file.
TEST(Faults, FullOrReadOnlyDiskKeepsThePreviousFile) {
  test::TempDir dir;
  const std::string mnt = dir.file("small");
  ASSERT_EQ(test::runCommand("mkdir -p " + mnt), 0);
  if (test::runCommand("mount -t tmpfs -o size=64k tmpfs " + mnt + " 2>/dev/null") != 0) {
    GTEST_SKIP() << "cannot mount a small tmpfs here (needs root in a machine that allows it)";
  }
  io::writeGaussianPly(dir.file("small_model.ply"), test::randomGaussians(4, 1));
  io::writeGaussianPly(dir.file("big_model.ply"), test::randomGaussians(400, 2));  // ~150 KB
  std::string out;
  ASSERT_EQ(test::runCommand(
                kCli + " convert " + dir.file("small_model.ply") + " " + mnt + "/model.ply", &out),
            0)
      << out;
  const std::string before = test::readFile(mnt + "/model.ply");
  EXPECT_EQ(test::runCommand(
                kCli + " convert " + dir.file("big_model.ply") + " " + mnt + "/model.ply", &out),
            1);
  EXPECT_NE(out.find("model.ply: write: expected all bytes written"), std::string::npos) << out;
  EXPECT_EQ(test::readFile(mnt + "/model.ply"), before);
  std::string listing;
  test::runCommand("ls " + mnt, &listing);
  EXPECT_EQ(listing, "model.ply\n");  // no temporary file left behind
  ASSERT_EQ(test::runCommand("mount -o remount,ro " + mnt), 0);
  EXPECT_EQ(test::runCommand(
                kCli + " convert " + dir.file("small_model.ply") + " " + mnt + "/model.pcd", &out),
            1);
  EXPECT_NE(out.find("model.pcd: open for writing"), std::string::npos) << out;
  test::runCommand("umount " + mnt);
}

}  // namespace
}  // namespace sadsplat
