// The experiment tables: runs read from RESULTS/<scene>/<config>_t<seed>/metrics.json, and the
// Markdown rows computed by hand.
#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/eval/experiment_table.h"
#include "sadsplat/io/filesystem.h"
#include "test_support/test_support.h"

namespace sadsplat {
namespace {

void writeMetrics(const std::string& dir, double miou, double psnr, int gaussians,
                  int large_floaters) {
  io::makeDirectory(dir);
  test::writeFile(
      dir + "/metrics.json",
      "{\"miou\": " + std::to_string(miou) + ", \"psnr\": " + std::to_string(psnr) +
          ", \"ssim\": 0.9, \"num_gaussians\": " + std::to_string(gaussians) +
          ", \"floaters\": {\"larger_than_10pct_extent\": " + std::to_string(large_floaters) +
          "}, \"per_class_iou\": {\"road\": 0.5, \"tree\": null}}");
}

TEST(ExperimentTable, MeanAndStdPerSceneAndKindWithTheBaselineFirst) {
  test::TempDir dir;
  const std::string root = dir.path();
  io::makeDirectory(root + "/city_0");
  writeMetrics(root + "/city_0/none_t0", 0.69, 30.0, 1000, 4);
  writeMetrics(root + "/city_0/none_t1", 0.71, 32.0, 1200, 6);
  writeMetrics(root + "/city_0/full_t0", 0.80, 29.0, 100, 0);
  writeMetrics(root + "/city_0/full_t1", 0.82, 29.0, 120, 2);
  io::makeDirectory(root + "/city_0/full_t2");  // unfinished: no metrics.json, skipped
  io::makeDirectory(root + "/port_1");
  writeMetrics(root + "/port_1/none_t0", 0.5, 20.0, 10, 0);

  const auto runs = eval::readExperimentRuns(root);
  ASSERT_EQ(runs.size(), 5u);
  EXPECT_EQ(runs[0].scene, "city_0");
  EXPECT_EQ(runs[0].kind, "city");
  EXPECT_EQ(runs[0].config, "full");
  EXPECT_EQ(runs[0].training_seed, 0);
  EXPECT_DOUBLE_EQ(runs[0].gaussians, 100);
  EXPECT_DOUBLE_EQ(runs[0].class_iou.at("road"), 0.5);
  EXPECT_EQ(runs[0].class_iou.count("tree"), 0u);  // null: not in the test views

  const eval::MeanStd m = eval::meanStd({1, 2, 3});
  EXPECT_DOUBLE_EQ(m.mean, 2);
  EXPECT_DOUBLE_EQ(m.std, 1);
  EXPECT_EQ(eval::meanStd({5}).std, 0);

  const std::string text = eval::experimentTables(runs, "none");
  // mIoU 69 / 71 -> 70.00 ± 1.41; Gaussians 1000 / 1200 -> 1100 ± 141; full: 110, 10.0x fewer.
  EXPECT_NE(text.find("| city_0 | none | 2 | 70.00 ± 1.41 | 31.00 ± 1.41 | 0.900 ± 0.000 | "
                      "1100 ± 141 | 1.0× | 5 ± 1 |"),
            std::string::npos)
      << text;
  EXPECT_NE(text.find("| city_0 | full | 2 | 81.00 ± 1.41 | 29.00 ± 0.00 | 0.900 ± 0.000 | "
                      "110 ± 14 | 10.0× | 1 ± 1 |"),
            std::string::npos)
      << text;
  EXPECT_LT(text.find("| city_0 | none |"), text.find("| city_0 | full |")) << "baseline first";
  EXPECT_NE(text.find("| port | none | 1 | 50.00 ± 0.00 |"), std::string::npos) << text;
  EXPECT_NE(text.find("Per-class IoU %, city"), std::string::npos) << text;
  EXPECT_NE(text.find("| full | 50.0 |"), std::string::npos) << text;
}

// Each configuration against the baseline on the same scene, means over the training seeds;
// scenes without baseline runs give no points.
TEST(ExperimentTable, FrontierPointsCompareEachSceneWithItsBaseline) {
  test::TempDir dir;
  const std::string root = dir.path();
  io::makeDirectory(root + "/city_0");
  writeMetrics(root + "/city_0/none_t0", 0.70, 32.0, 1000, 0);
  writeMetrics(root + "/city_0/none_t1", 0.72, 30.0, 1400, 0);
  writeMetrics(root + "/city_0/full_t0", 0.80, 29.0, 100, 0);
  writeMetrics(root + "/city_0/full_t1", 0.84, 30.0, 140, 0);
  io::makeDirectory(root + "/port_1");
  writeMetrics(root + "/port_1/full_t0", 0.9, 25.0, 10, 0);  // no baseline here

  const auto points = eval::frontierPoints(eval::readExperimentRuns(root), "none");
  ASSERT_EQ(points.size(), 2u);
  EXPECT_EQ(points[0].scene, "city_0");
  EXPECT_EQ(points[0].config, "full");
  EXPECT_EQ(points[0].runs, 2);
  EXPECT_NEAR(points[0].fewer, 1200.0 / 120.0, 1e-9);  // mean counts 1200 / 120
  EXPECT_NEAR(points[0].miou_change, 82.0 - 71.0, 1e-9);
  EXPECT_NEAR(points[0].psnr_change, 29.5 - 31.0, 1e-9);
  EXPECT_EQ(points[1].config, "none");
  EXPECT_NEAR(points[1].fewer, 1.0, 1e-12);
  EXPECT_NEAR(points[1].psnr_change, 0.0, 1e-12);
  EXPECT_TRUE(eval::frontierPoints(eval::readExperimentRuns(root), "nothing").empty());
}

TEST(ExperimentTable, MalformedFoldersAndMetricsAreClearErrors) {
  test::TempDir dir;
  io::makeDirectory(dir.file("city_0"));
  writeMetrics(dir.file("city_0/full"), 0.5, 20, 10, 0);  // no _t<seed>
  EXPECT_THROW(eval::readExperimentRuns(dir.path()), Error);

  test::TempDir other;
  io::makeDirectory(other.file("city_0"));
  io::makeDirectory(other.file("city_0/full_t0"));
  test::writeFile(other.file("city_0/full_t0/metrics.json"), "{\"miou\": \"high\"}");
  try {
    eval::readExperimentRuns(other.path());
    FAIL();
  } catch (const Error& e) {
    EXPECT_EQ(e.field(), "miou");
  }
  EXPECT_THROW(eval::readExperimentRuns(other.file("missing")), Error);
}

}  // namespace
}  // namespace sadsplat
