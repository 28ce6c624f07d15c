// The scene cache: exact round trip and every kind of damaged file.
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <functional>

#include "sadsplat/common/error.h"
#include "sadsplat/io/scene_cache.h"
#include "sadsplat/io/scene_import.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

io::Scene syntheticScene() {
  io::Scene scene;
  scene.source = "synthetic";
  scene.classes = {{"road", {1, 2, 3}, "a road"}, {"roof", {4, 5, 6}, "a roof"}};
  for (int i = 0; i < 3; ++i) {
    io::View v;
    v.name = "v" + std::to_string(i) + ".png";
    v.camera.width = 5 + i;
    v.camera.height = 4;
    v.camera.fx = 10.5 + i;
    v.camera.fy = 11.25;
    v.camera.cx = 2.5;
    v.camera.cy = 2.0;
    v.camera.qvec = {0.5, 0.5, -0.5, 0.5};
    v.camera.tvec = {1e-3, -2.0, 3.0 + i};
    const auto n = static_cast<std::size_t>(v.camera.width * v.camera.height);
    v.rgb = {v.camera.width, 4, 3, std::vector<std::uint8_t>(n * 3)};
    for (std::size_t k = 0; k < n * 3; ++k) v.rgb.pixels[k] = static_cast<std::uint8_t>(k * 7 + i);
    v.mask = {v.camera.width, 4, 1, std::vector<std::uint8_t>(n, 255)};
    if (i != 1) {
      v.labels = {v.camera.width, 4, 1, std::vector<std::uint8_t>(n)};
      for (std::size_t k = 0; k < n; ++k) v.labels.pixels[k] = k % 3 == 2 ? 255 : k % 2;
    }
    v.train = i != 2;
    v.test = i == 2;
    v.labelled = i == 0;
    scene.views.push_back(v);
  }
  scene.points = {{{1.f, 2.f, 3.f}, {9, 8, 7}}, {{-1.f, 0.5f, 1e-8f}, {0, 255, 1}}};
  return scene;
}

void expectCacheError(const std::string& path, const std::string& needle) {
  try {
    io::readSceneCache(path);
    FAIL() << "expected an error containing " << needle;
  } catch (const Error& e) {
    EXPECT_EQ(e.file(), path);
    EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
  }
}

// Rewrites the header checksum so that only the deliberate damage is detected.
void fixChecksum(std::string& bytes) {
  const std::uint64_t sum = io::fnv1a64(bytes.data() + 32, bytes.size() - 32);
  std::memcpy(&bytes[24], &sum, 8);
}

TEST(SceneCache, RoundTripIsExact) {
  test::TempDir dir;
  const io::Scene scene = syntheticScene();
  io::writeSceneCache(dir.file("s.cache"), scene);
  EXPECT_TRUE(io::isSceneCache(dir.file("s.cache")));
  const io::Scene back = io::readSceneCache(dir.file("s.cache"));
  EXPECT_EQ(back.source, "synthetic");
  ASSERT_EQ(back.classes.size(), 2u);
  EXPECT_EQ(back.classes[1].name, "roof");
  EXPECT_EQ(back.classes[1].color, scene.classes[1].color);
  EXPECT_EQ(back.classes[1].prompt, "a roof");
  ASSERT_EQ(back.views.size(), 3u);
  for (std::size_t i = 0; i < 3; ++i) {
    const auto &a = scene.views[i], &b = back.views[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera.width, b.camera.width);
    EXPECT_EQ(a.camera.fx, b.camera.fx);
    EXPECT_EQ(a.camera.cy, b.camera.cy);
    EXPECT_EQ(a.camera.qvec, b.camera.qvec);
    EXPECT_EQ(a.camera.tvec, b.camera.tvec);
    EXPECT_EQ(a.rgb.pixels, b.rgb.pixels);
    EXPECT_EQ(a.mask.pixels, b.mask.pixels);
    EXPECT_EQ(a.labels.pixels, b.labels.pixels);
    EXPECT_EQ(a.train, b.train);
    EXPECT_EQ(a.test, b.test);
    EXPECT_EQ(a.labelled, b.labelled);
  }
  ASSERT_EQ(back.points.size(), 2u);
  EXPECT_EQ(back.points[1].xyz, scene.points[1].xyz);
  EXPECT_EQ(back.points[1].rgb, scene.points[1].rgb);
}

// data/tiny_scene.cache lets builds without OpenCV (the GPU machine) train on the fixture; it
// must stay what `sadsplat import data/tiny_scene --scale 1` gives.
TEST(SceneCache, CommittedTinySceneCacheMatchesAFreshImport) {
  if (!io::haveSceneImport()) GTEST_SKIP() << "built without OpenCV";
  const std::string data = SADSPLAT_TEST_DATA_DIR;
  const io::Scene fresh = io::importScene(data + "/tiny_scene");
  const io::Scene cached = io::readSceneCache(data + "/tiny_scene.cache");
  ASSERT_EQ(fresh.views.size(), cached.views.size());
  ASSERT_EQ(fresh.classes.size(), cached.classes.size());
  for (std::size_t i = 0; i < fresh.views.size(); ++i) {
    const auto &a = fresh.views[i], &b = cached.views[i];
    EXPECT_EQ(a.name, b.name);
    EXPECT_EQ(a.camera.fx, b.camera.fx);
    EXPECT_EQ(a.camera.qvec, b.camera.qvec);
    EXPECT_EQ(a.camera.tvec, b.camera.tvec);
    EXPECT_EQ(a.rgb.pixels, b.rgb.pixels) << a.name;
    EXPECT_EQ(a.mask.pixels, b.mask.pixels) << a.name;
    EXPECT_EQ(a.labels.pixels, b.labels.pixels) << a.name;
    EXPECT_EQ(a.train, b.train);
    EXPECT_EQ(a.test, b.test);
    EXPECT_EQ(a.labelled, b.labelled);
  }
  ASSERT_EQ(fresh.points.size(), cached.points.size());
  for (std::size_t i = 0; i < fresh.points.size(); ++i)
    EXPECT_EQ(fresh.points[i].xyz, cached.points[i].xyz);
}

TEST(SceneCache, DamagedFilesAreRejectedWithTheReason) {
  test::TempDir dir;
  expectCacheError(dir.file("none.cache"), "existing, readable file");
  io::writeSceneCache(dir.file("s.cache"), syntheticScene());
  const std::string good = test::readFile(dir.file("s.cache"));

  std::string bytes = good;
  bytes[0] = 'X';
  test::writeFile(dir.file("magic.cache"), bytes);
  expectCacheError(dir.file("magic.cache"), "magic");

  bytes = good;
  bytes[8] = 99;  // version
  test::writeFile(dir.file("version.cache"), bytes);
  expectCacheError(dir.file("version.cache"), "version: expected 1");

  test::writeFile(dir.file("short.cache"), good.substr(0, good.size() - 7));
  expectCacheError(dir.file("short.cache"), "truncated");

  bytes = good;
  bytes[bytes.size() - 20] ^= 0x40;
  test::writeFile(dir.file("flip.cache"), bytes);
  expectCacheError(dir.file("flip.cache"), "checksum");
}

TEST(SceneCache, ChecksSemanticValidityOfWellFormedFiles) {
  test::TempDir dir;
  io::Scene scene = syntheticScene();
  scene.views[2].camera.fx = std::nan("");
  io::writeSceneCache(dir.file("nan.cache"), scene);
  expectCacheError(dir.file("nan.cache"), "fx: expected a finite number");

  // Values that parse but are no camera or class list (found by hand-made caches that trained
  // without a word): a zero quaternion, a denormal focal length, more classes than a byte holds.
  scene = syntheticScene();
  scene.views[1].camera.qvec = {0, 0, 0, 0};
  io::writeSceneCache(dir.file("quat.cache"), scene);
  expectCacheError(dir.file("quat.cache"), "qvec: expected a non-zero rotation quaternion");
  scene = syntheticScene();
  scene.views[0].camera.fy = 5e-324;
  io::writeSceneCache(dir.file("focal.cache"), scene);
  expectCacheError(dir.file("focal.cache"), "focal lengths of at least 0.001 px");
  scene = syntheticScene();
  scene.classes.resize(5000, scene.classes[0]);
  io::writeSceneCache(dir.file("classes.cache"), scene);
  expectCacheError(dir.file("classes.cache"), "0 to 255 classes");

  scene = syntheticScene();
  scene.views[0].labels.pixels[3] = 7;  // only 2 classes
  io::writeSceneCache(dir.file("label.cache"), scene);
  expectCacheError(dir.file("label.cache"), "class id below 2");

  // A damaged chunk size inside a payload whose checksum is (re)valid.
  io::writeSceneCache(dir.file("s.cache"), syntheticScene());
  std::string bytes = test::readFile(dir.file("s.cache"));
  const std::uint64_t huge = 1ull << 40;
  std::memcpy(&bytes[32 + 4], &huge, 8);  // size of the first chunk
  fixChecksum(bytes);
  test::writeFile(dir.file("chunk.cache"), bytes);
  expectCacheError(dir.file("chunk.cache"), "truncated or corrupt");
}

// The checksum is FNV-1a-64 as published (test vectors of the reference implementation); the
// committed fixture is a version-1 file (its checksum used a wrong offset basis) and still reads.
TEST(SceneCache, ChecksumIsFnv1a64AndVersion1FilesStillRead) {
  EXPECT_EQ(io::fnv1a64("", 0), 0xcbf29ce484222325ull);
  EXPECT_EQ(io::fnv1a64("a", 1), 0xaf63dc4c8601ec8cull);
  EXPECT_EQ(io::fnv1a64("foobar", 6), 0x85944171f73967e8ull);
  const std::string v1 = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  EXPECT_EQ(io::sceneCacheVersion(v1), 1u);
  const io::Scene scene = io::readSceneCache(v1);
  test::TempDir dir;
  io::writeSceneCache(dir.file("v3.cache"), scene);
  EXPECT_EQ(io::sceneCacheVersion(dir.file("v3.cache")), 3u);
  const std::string bytes = test::readFile(dir.file("v3.cache"));
  std::uint64_t stored;
  std::memcpy(&stored, bytes.data() + 24, 8);
  EXPECT_EQ(stored, io::fnv1a64(bytes.data() + 32, bytes.size() - 32));
  EXPECT_EQ(io::readSceneCache(dir.file("v3.cache")).views.size(), scene.views.size());
}

// Version 3 stores the images losslessly compressed: the fixture's rendered views (a version-1
// file of raw planes) come back pixel for pixel from a file well under half the size.
TEST(SceneCache, CompressedImagesAreLosslessAndSmaller) {
  const std::string v1 = std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache";
  const io::Scene scene = io::readSceneCache(v1);
  test::TempDir dir;
  io::writeSceneCache(dir.file("v3.cache"), scene);
  const io::Scene back = io::readSceneCache(dir.file("v3.cache"));
  ASSERT_EQ(back.views.size(), scene.views.size());
  for (std::size_t i = 0; i < scene.views.size(); ++i) {
    EXPECT_EQ(back.views[i].rgb.pixels, scene.views[i].rgb.pixels);
    EXPECT_EQ(back.views[i].mask.pixels, scene.views[i].mask.pixels);
    EXPECT_EQ(back.views[i].labels.pixels, scene.views[i].labels.pixels);
  }
  const double ratio =
      double(test::readFile(dir.file("v3.cache")).size()) / test::readFile(v1).size();
  EXPECT_LT(ratio, 0.5) << ratio;
}

// A compressed image whose stream is damaged (the checksum made valid again) is an error naming
// the view's image, not garbage pixels or a crash.
TEST(SceneCache, DamagedCompressedImagesAreErrors) {
  test::TempDir dir;
  io::writeSceneCache(dir.file("s.cache"), syntheticScene());
  std::string bytes = test::readFile(dir.file("s.cache"));
  // The first VIEW chunk: tag, size, name "v0.png", width, height, 4 + 4 + 3 doubles, roles,
  // has-labels, then the rgb block's size and bytes.
  const std::size_t view = bytes.find("VIEW");
  ASSERT_NE(view, std::string::npos);
  const std::size_t block = view + 4 + 8 + 4 + 6 + 8 + 11 * 8 + 2;
  std::uint64_t size;
  std::memcpy(&size, &bytes[block], 8);
  ASSERT_GT(size, 0u);
  ASSERT_LT(block + 8 + size, bytes.size());
  std::string zeroed = bytes;
  std::memset(&zeroed[block + 8], 0, size);  // a stored deflate block with LEN != ~NLEN
  fixChecksum(zeroed);
  test::writeFile(dir.file("zeroed.cache"), zeroed);
  expectCacheError(dir.file("zeroed.cache"), "rgb");
  std::string huge = bytes;
  const std::uint64_t big = 1ull << 40;
  std::memcpy(&huge[block], &big, 8);
  fixChecksum(huge);
  test::writeFile(dir.file("huge.cache"), huge);
  expectCacheError(dir.file("huge.cache"), "truncated or corrupt");
}

// A view with pseudo-labels: view 1 of syntheticScene (no label map) gets two targets.
io::Scene sceneWithPseudoLabels() {
  io::Scene scene = syntheticScene();
  io::View& v = scene.views[1];
  io::ViewPseudoLabels& p = v.pseudo;
  p.backend = "builtin";
  p.num_targets = 2;
  p.num_classes = 2;
  p.feature_dim = 1;
  const auto n = static_cast<std::size_t>(v.camera.width * v.camera.height);
  for (std::size_t k = 0; k < n; ++k) p.region.push_back(static_cast<std::int32_t>(k % 3) - 1);
  p.scores = {0.25f, 0.75f, 0.5f, 0.5f};
  p.features = {0.125f, -2.0f};
  p.kept = {1, 0};
  return scene;
}

// A cache read without pixels holds what the whole read holds but the pixels; each view read on
// its own is the whole read's view, for version 3 and for the version-1 fixture.
TEST(SceneCache, ViewsReadOneAtATimeAreTheWholeReadsViews) {
  test::TempDir dir;
  io::writeSceneCache(dir.file("s.cache"), sceneWithPseudoLabels());
  for (const std::string& path :
       {dir.file("s.cache"), std::string(SADSPLAT_TEST_DATA_DIR) + "/tiny_scene.cache"}) {
    const io::Scene whole = io::readSceneCache(path);
    const io::Scene lazy = io::readSceneCacheWithoutPixels(path);
    EXPECT_EQ(lazy.source, whole.source);
    ASSERT_EQ(lazy.classes.size(), whole.classes.size());
    ASSERT_EQ(lazy.points.size(), whole.points.size());
    EXPECT_EQ(lazy.points.back().xyz, whole.points.back().xyz);
    ASSERT_EQ(lazy.views.size(), whole.views.size());
    int with_pseudo = 0;
    for (std::size_t i = 0; i < whole.views.size(); ++i) {
      const io::View &a = whole.views[i], &b = lazy.views[i];
      EXPECT_EQ(b.name, a.name);
      EXPECT_EQ(b.camera.tvec, a.camera.tvec);
      EXPECT_EQ(b.train, a.train);
      EXPECT_EQ(b.labelled, a.labelled);
      EXPECT_TRUE(b.rgb.empty() && b.mask.empty() && b.labels.empty() && b.pseudo.empty());
      ASSERT_TRUE(b.pixels_in_cache != nullptr);
      EXPECT_EQ(b.hasLabels(), a.hasLabels());
      EXPECT_EQ(b.hasPseudoLabels(), a.hasPseudoLabels());
      const io::View c = io::readViewPixels(b);
      EXPECT_TRUE(c.pixels_in_cache == nullptr);
      EXPECT_EQ(c.rgb.pixels, a.rgb.pixels) << path << " " << a.name;
      EXPECT_EQ(c.mask.pixels, a.mask.pixels);
      EXPECT_EQ(c.labels.pixels, a.labels.pixels);
      EXPECT_EQ(c.pseudo.region, a.pseudo.region);
      EXPECT_EQ(c.pseudo.scores, a.pseudo.scores);
      EXPECT_EQ(c.pseudo.features, a.pseudo.features);
      EXPECT_EQ(c.pseudo.kept, a.pseudo.kept);
      with_pseudo += !c.pseudo.empty();
    }
    if (path == dir.file("s.cache")) {
      EXPECT_EQ(with_pseudo, 1);
    }
  }
}

// Damage: the whole file's checksum is checked when it is opened; a damaged image whose checksum
// was made valid again is found when its view is read, naming the file and the image; a file
// that changed after the open is an error naming the view.
TEST(SceneCache, ViewsReadOneAtATimeReportDamage) {
  test::TempDir dir;
  io::writeSceneCache(dir.file("s.cache"), sceneWithPseudoLabels());
  const std::string good = test::readFile(dir.file("s.cache"));
  const auto expectError = [](const std::function<void()>& read, const std::string& file,
                              const std::string& needle) {
    try {
      read();
      ADD_FAILURE() << "expected an error containing " << needle;
    } catch (const Error& e) {
      EXPECT_EQ(e.file(), file);
      EXPECT_NE(std::string(e.what()).find(needle), std::string::npos) << e.what();
    }
  };
  std::string bytes = good;
  bytes[bytes.size() - 20] ^= 0x40;
  test::writeFile(dir.file("flip.cache"), bytes);
  expectError([&] { io::readSceneCacheWithoutPixels(dir.file("flip.cache")); },
              dir.file("flip.cache"), "checksum");
  test::writeFile(dir.file("short.cache"), good.substr(0, good.size() - 7));
  expectError([&] { io::readSceneCacheWithoutPixels(dir.file("short.cache")); },
              dir.file("short.cache"), "truncated");
  expectError([&] { io::readSceneCacheWithoutPixels(dir.file("none.cache")); },
              dir.file("none.cache"), "existing, readable file");

  // The first view's rgb block zeroed (see DamagedCompressedImagesAreErrors).
  const std::size_t block = good.find("VIEW") + 4 + 8 + 4 + 6 + 8 + 11 * 8 + 2;
  std::uint64_t size;
  std::memcpy(&size, &good[block], 8);
  bytes = good;
  std::memset(&bytes[block + 8], 0, size);
  fixChecksum(bytes);
  test::writeFile(dir.file("zeroed.cache"), bytes);
  const io::Scene zeroed = io::readSceneCacheWithoutPixels(dir.file("zeroed.cache"));
  EXPECT_NO_THROW(io::readViewPixels(zeroed.views[1]));
  expectError([&] { io::readViewPixels(zeroed.views[0]); }, dir.file("zeroed.cache"), "rgb");

  const io::Scene opened = io::readSceneCacheWithoutPixels(dir.file("s.cache"));
  test::writeFile(dir.file("s.cache"), good.substr(0, good.size() / 2));
  expectError([&] { io::readViewPixels(opened.views[2]); }, dir.file("s.cache"),
              "view v2.png VIEW chunk: expected the bytes found when the cache was opened");
}

}  // namespace
}  // namespace sadsplat
