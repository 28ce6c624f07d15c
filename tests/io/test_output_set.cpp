// Outputs written as a set (ortho's rasters, render's folders): a failure keeps the old set whole
// and leaves no staging folder; a rerun replaces the whole set, members it does not write included.
#include <gtest/gtest.h>

#include <filesystem>
#include <stdexcept>

#include "sadsplat/io/atomic_file.h"
#include "sadsplat/io/filesystem.h"
#include "sadsplat/io/output_set.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

namespace fs = std::filesystem;

std::size_t entriesIn(const std::string& dir) {
  std::size_t n = 0;
  for (const auto& e : fs::directory_iterator(dir)) n += e.path().filename() != "" ? 1 : 0;
  return n;
}

TEST(OutputSet, ARerunReplacesTheSetAndAFailureKeepsTheOldOne) {
  test::TempDir tmp;
  const std::string out = tmp.file("out");
  {
    io::OutputSet set(out, {"dsm.tif", "ortho.json", "rgb"});
    test::writeFile(set.path("dsm.tif"), "dsm at 1.0 m");
    test::writeFile(set.path("ortho.json"), "{\"gsd\": 1.0}");
    io::makeDirectory(set.path("rgb"));
    test::writeFile(set.path("rgb") + "/a.png", "a");
    EXPECT_FALSE(fs::exists(out + "/dsm.tif"));  // nothing in place before commit
    set.commit();
  }
  test::writeFile(out + "/notes.txt", "the user's own file");
  EXPECT_EQ(test::readFile(out + "/dsm.tif"), "dsm at 1.0 m");
  EXPECT_EQ(entriesIn(out), 4u);  // dsm.tif, ortho.json, rgb, notes.txt: no staging folder

  // A run that fails half-way: the old set is untouched, the staging folder is gone.
  try {
    io::OutputSet set(out, {"dsm.tif", "ortho.json", "rgb"});
    test::writeFile(set.path("dsm.tif"), "dsm at 0.34 m");
    throw std::runtime_error("disk full");
  } catch (const std::runtime_error&) {
  }
  EXPECT_EQ(test::readFile(out + "/dsm.tif"), "dsm at 1.0 m");
  EXPECT_EQ(entriesIn(out), 4u);

  // A rerun that writes only ortho.json and another rgb folder: the old dsm.tif and rgb/a.png go,
  // the user's file stays.
  {
    io::OutputSet set(out, {"dsm.tif", "ortho.json", "rgb"});
    test::writeFile(set.path("ortho.json"), "{\"gsd\": 0.34}");
    io::makeDirectory(set.path("rgb"));
    test::writeFile(set.path("rgb") + "/b.png", "b");
    set.commit();
  }
  EXPECT_FALSE(fs::exists(out + "/dsm.tif"));
  EXPECT_FALSE(fs::exists(out + "/rgb/a.png"));
  EXPECT_EQ(test::readFile(out + "/rgb/b.png"), "b");
  EXPECT_EQ(test::readFile(out + "/ortho.json"), "{\"gsd\": 0.34}");
  EXPECT_EQ(test::readFile(out + "/notes.txt"), "the user's own file");
  EXPECT_EQ(entriesIn(out), 3u);
}

}  // namespace
}  // namespace sadsplat
