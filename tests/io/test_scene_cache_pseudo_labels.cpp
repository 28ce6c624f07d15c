#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/io/file_info.h"
#include "sadsplat/io/scene_cache.h"
#include "test_support/test_support.h"

namespace io = sadsplat::io;

namespace {
io::Scene sceneWithPseudoLabels() {
  io::Scene s;
  s.source = "test";
  s.classes = {{"a", {1, 2, 3}, "a"}, {"b", {4, 5, 6}, "b"}};
  io::View v;
  v.name = "v0.png";
  v.camera.width = 3;
  v.camera.height = 2;
  v.camera.fx = v.camera.fy = 1;
  v.rgb = {3, 2, 3, std::vector<std::uint8_t>(18, 7)};
  v.mask = {3, 2, 1, std::vector<std::uint8_t>(6, 255)};
  v.train = true;
  v.pseudo.backend = "builtin";
  v.pseudo.region = {0, 0, 1, 1, -1, 1};
  v.pseudo.num_targets = 2;
  v.pseudo.num_classes = 2;
  v.pseudo.scores = {0.9f, 0.1f, 0.3f, 0.7f};
  v.pseudo.feature_dim = 1;
  v.pseudo.features = {-1.5f, 2.5f};
  v.pseudo.kept = {1, 0};
  s.views.push_back(v);
  io::View w = v;
  w.name = "v1.png";
  w.pseudo = {};
  s.views.push_back(w);
  return s;
}
}  // namespace

TEST(SceneCachePseudoLabels, RoundTripIsExact) {
  sadsplat::test::TempDir dir;
  const io::Scene s = sceneWithPseudoLabels();
  io::writeSceneCache(dir.file("s.cache"), s);
  const io::Scene r = io::readSceneCache(dir.file("s.cache"));
  ASSERT_EQ(r.views.size(), 2u);
  const io::ViewPseudoLabels& p = r.views[0].pseudo;
  EXPECT_EQ(p.backend, "builtin");
  EXPECT_EQ(p.region, s.views[0].pseudo.region);
  EXPECT_EQ(p.scores, s.views[0].pseudo.scores);
  EXPECT_EQ(p.features, s.views[0].pseudo.features);
  EXPECT_EQ(p.kept, s.views[0].pseudo.kept);
  EXPECT_TRUE(r.views[1].pseudo.empty());
  EXPECT_EQ(p.labelMap(), (std::vector<std::int16_t>{0, 0, -1, -1, -1, -1}));
  EXPECT_EQ(p.maxScoreMap(), (std::vector<float>{0.9f, 0.9f, 0.7f, 0.7f, 0.0f, 0.7f}));
}

TEST(SceneCachePseudoLabels, InvalidPseudoLabelsAreRejected) {
  sadsplat::test::TempDir dir;
  io::Scene s = sceneWithPseudoLabels();
  s.views[0].pseudo.region[2] = 5;  // no such target
  EXPECT_THROW(io::writeSceneCache(dir.file("bad.cache"), s), sadsplat::Error);
  s = sceneWithPseudoLabels();
  s.views[0].pseudo.scores[0] = 1.5f;
  try {
    io::writeSceneCache(dir.file("bad.cache"), s);
    FAIL();
  } catch (const sadsplat::Error& e) {
    EXPECT_NE(std::string(e.what()).find("scores"), std::string::npos) << e.what();
  }
}

// `sadsplat info` on a cache with pseudo-labels: one view of 6 pixels has them, target 0 (class a,
// 2 pixels) kept, target 1 not: 1 of 2 targets, 2 of 6 pixels = 33.3 %.
TEST(SceneCachePseudoLabels, InfoSummarisesThePseudoLabels) {
  sadsplat::test::TempDir dir;
  io::writeSceneCache(dir.file("s.cache"), sceneWithPseudoLabels());
  const std::string info = io::describeFile(dir.file("s.cache"));
  EXPECT_NE(info.find("pseudo-labels: 1 views (builtin), 1 of 2 targets kept, 33.3 % of their "
                      "pixels labelled"),
            std::string::npos)
      << info;
  EXPECT_NE(info.find("0 a rgb(1,2,3) \"a\", 2 pseudo-labelled pixels"), std::string::npos) << info;
  EXPECT_NE(info.find("1 b rgb(4,5,6) \"b\", 0 pseudo-labelled pixels"), std::string::npos) << info;

  io::Scene plain = sceneWithPseudoLabels();
  plain.views[0].pseudo = {};
  io::writeSceneCache(dir.file("plain.cache"), plain);
  const std::string plain_info = io::describeFile(dir.file("plain.cache"));
  EXPECT_EQ(plain_info.find("pseudo"), std::string::npos) << plain_info;
}
