#include <gtest/gtest.h>

#include "sadsplat/common/error.h"
#include "sadsplat/eval/metrics.h"

namespace sadsplat {
namespace {

TEST(ConfusionMatrix, MetricsMatchAHandComputedExample) {
  // gt:   0 0 0 1 1 2 255 2
  // pred: 0 0 1 1 0 2   1 2
  const std::uint8_t gt[] = {0, 0, 0, 1, 1, 2, 255, 2};
  const std::int64_t pred[] = {0, 0, 1, 1, 0, 2, 1, 2};
  eval::ConfusionMatrix cm(4);  // class 3 never occurs
  cm.add(gt, pred, 8);
  EXPECT_EQ(cm.total(), 7);
  EXPECT_EQ(cm.at(0, 0), 2);
  EXPECT_EQ(cm.at(0, 1), 1);
  EXPECT_EQ(cm.at(1, 0), 1);
  // IoU: class 0: 2 / (2 + 1 + 1) = 0.5; class 1: 1 / (1 + 1 + 1) = 1/3; class 2: 1; class 3:
  // absent.
  const auto iou = cm.perClassIou();
  EXPECT_DOUBLE_EQ(iou[0], 0.5);
  EXPECT_DOUBLE_EQ(iou[1], 1.0 / 3.0);
  EXPECT_DOUBLE_EQ(iou[2], 1.0);
  EXPECT_EQ(iou[3], -1.0);
  EXPECT_DOUBLE_EQ(cm.meanIou(), (0.5 + 1.0 / 3.0 + 1.0) / 3.0);
  // Accuracy per gt class: 2/3, 1/2, 2/2.
  EXPECT_DOUBLE_EQ(cm.meanAccuracy(), (2.0 / 3.0 + 0.5 + 1.0) / 3.0);
  EXPECT_DOUBLE_EQ(cm.overallAccuracy(), 5.0 / 7.0);
}

TEST(ConfusionMatrix, RejectsPredictionsOutsideTheClasses) {
  eval::ConfusionMatrix cm(2);
  const std::uint8_t gt[] = {0};
  const std::int64_t pred[] = {5};
  EXPECT_THROW(cm.add(gt, pred, 1), Error);
}

}  // namespace
}  // namespace sadsplat

namespace sadsplat {
namespace {

TEST(ConfusionMatrix, AddingAMatrixCountsAsAddingItsPixels) {
  const std::uint8_t gt_a[] = {0, 1, 2, 255}, gt_b[] = {2, 2, 0, 1};
  const std::int64_t pred_a[] = {0, 2, 2, 1}, pred_b[] = {2, 0, 0, 1};
  eval::ConfusionMatrix a(3), b(3), all(3);
  a.add(gt_a, pred_a, 4);
  b.add(gt_b, pred_b, 4);
  all.add(gt_a, pred_a, 4);
  all.add(gt_b, pred_b, 4);
  a.add(b);
  for (int g = 0; g < 3; ++g)
    for (int p = 0; p < 3; ++p) EXPECT_EQ(a.at(g, p), all.at(g, p)) << g << " " << p;
  EXPECT_EQ(a.total(), 7);
  EXPECT_THROW(a.add(eval::ConfusionMatrix(4)), Error);
}

TEST(ConfusionWithin, CountsOnlyTheCellsNearTheCentre) {
  // 4 x 4 cells of 1 m: class 1 in the middle four, 0 around. The prediction misses one middle
  // cell and calls one cell beside them 1; another cell beside them is uncovered (no class).
  const int w = 4, h = 4;
  const auto at = [&](int x, int y) { return static_cast<std::size_t>(y) * w + x; };
  std::vector<std::uint8_t> truth(16, 0), pred(16, 0), covered(16, 1);
  for (int y = 1; y <= 2; ++y) {
    for (int x = 1; x <= 2; ++x) truth[at(x, y)] = 1, pred[at(x, y)] = 1;
  }
  pred[at(2, 2)] = 0;
  pred[at(3, 1)] = 1;
  covered[at(0, 1)] = 0, pred[at(0, 1)] = 255;
  // Radius 1: the middle four (centres 0.71 m out). Class 1: TP 3, FN 1 -> 0.75; class 0: FP 1 ->
  // 0.
  EXPECT_NEAR(eval::confusionWithin(truth, pred, covered, w, h, 1.0, 1.0, 2).meanIou(), 0.375,
              1e-12);
  // Radius 1.6: and the seven covered cells beside them (1.58 m out), not the corners (2.12 m).
  // Class 1: TP 3, FN 1, FP 1 -> 0.6; class 0: TP 6, FP 1, FN 1 -> 0.75.
  const eval::ConfusionMatrix m = eval::confusionWithin(truth, pred, covered, w, h, 1.0, 1.6, 2);
  EXPECT_EQ(m.total(), 11);
  EXPECT_NEAR(m.meanIou(), 0.675, 1e-12);
  // Everything: the corners are class 0, predicted 0.
  EXPECT_EQ(eval::confusionWithin(truth, pred, covered, w, h, 1.0, 10.0, 2).total(), 15);
  pred[at(1, 1)] = 7;  // not a class, where covered
  EXPECT_THROW(eval::confusionWithin(truth, pred, covered, w, h, 1.0, 1.0, 2), Error);
  EXPECT_THROW(eval::confusionWithin(truth, pred, {1, 1}, w, h, 1.0, 1.0, 2), Error);
}

}  // namespace
}  // namespace sadsplat
