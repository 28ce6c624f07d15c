#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
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
