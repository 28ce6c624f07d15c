// A surface model against the true heights: RMSE, median absolute error, NMAD and the errors
// away from the height steps, on grids small enough to work out by hand.
#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/common/error.h"
#include "sadsplat/eval/dsm_scores.h"

namespace sadsplat {
namespace {

TEST(DsmScores, StepCellsAreBothSidesOfAWall) {
  // A 10 m block in the middle of a 5 x 3 grid of ground at 0: the step cells are those whose
  // 3 x 3 neighbourhood holds both heights (the block and its ring), nothing else.
  std::vector<float> truth(15, 0.f);
  truth[7] = 10.f;
  const std::vector<std::uint8_t> step = eval::heightStepCells(truth, 5, 3, 2.0);
  const std::vector<std::uint8_t> expected = {0, 1, 1, 1, 0, 0, 1, 1, 1, 0, 0, 1, 1, 1, 0};
  EXPECT_EQ(step, expected);
  // A lower block (1.5 m) is no step at 2 m, and an unknown height (NaN) does not make one.
  truth[7] = 1.5f;
  truth[0] = NAN;
  for (std::uint8_t s : eval::heightStepCells(truth, 5, 3, 2.0)) EXPECT_EQ(s, 0);
}

TEST(DsmScores, ErrorsAllPerClassAndAwayFromSteps) {
  // One row: ground (class 1) at 0, a 10 m roof (class 0) beside it. Cells 1 and 2 hold the
  // step; errors 0.1, 5, 0, -1.
  const std::vector<float> truth = {0, 0, 10, 10};
  const std::vector<float> model = {0.1f, 5, 10, 9};
  const std::vector<std::uint8_t> classes = {1, 1, 0, 0};
  const std::vector<std::uint8_t> scored = {1, 1, 1, 1};
  const eval::DsmScores s = eval::scoreDsm(model, truth, classes, scored, 4, 1, 2);
  EXPECT_EQ(s.all.cells, 4u);
  EXPECT_NEAR(s.all.rmse_m, std::sqrt((0.01 + 25 + 0 + 1) / 4), 1e-6);
  EXPECT_NEAR(s.all.median_abs_m, (0.1 + 1) / 2, 1e-6);  // |e| sorted 0, 0.1, 1, 5
  // median error 0.05; |e - 0.05| sorted 0.05, 0.05, 1.05, 4.95
  EXPECT_NEAR(s.all.nmad_m, 1.4826 * (0.05 + 1.05) / 2, 1e-6);
  EXPECT_EQ(s.all.off_step_cells, 2u);
  EXPECT_NEAR(s.all.off_step_rmse_m, std::sqrt((0.01 + 1) / 2), 1e-6);
  ASSERT_EQ(s.per_class.size(), 2u);
  EXPECT_NEAR(s.per_class[1].rmse_m, std::sqrt(25.01 / 2), 1e-6);
  EXPECT_NEAR(s.per_class[1].off_step_rmse_m, 0.1, 1e-6);
  EXPECT_NEAR(s.per_class[0].rmse_m, std::sqrt(0.5), 1e-6);
  EXPECT_NEAR(s.per_class[0].off_step_rmse_m, 1.0, 1e-6);
}

TEST(DsmScores, SkipsUnscoredUnknownAndUnlabelledCells) {
  const std::vector<float> truth = {0, 0, 0, NAN};
  const std::vector<float> model = {1, NAN, 7, 3};
  const std::vector<std::uint8_t> classes = {0, 0, 255, 0};
  const std::vector<std::uint8_t> scored = {1, 1, 1, 1};
  eval::DsmScores s = eval::scoreDsm(model, truth, classes, scored, 4, 1, 1);
  EXPECT_EQ(s.all.cells, 1u);  // the model's NaN, class 255 and the unknown truth are skipped
  EXPECT_NEAR(s.all.rmse_m, 1.0, 1e-9);
  EXPECT_NEAR(s.all.nmad_m, 0.0, 1e-9);
  s = eval::scoreDsm(model, truth, classes, {0, 1, 1, 1}, 4, 1, 1);
  EXPECT_EQ(s.all.cells, 0u);
  EXPECT_EQ(s.per_class[0].cells, 0u);
  EXPECT_THROW(eval::scoreDsm(model, truth, classes, {1, 1}, 4, 1, 1), Error);
}

}  // namespace
}  // namespace sadsplat
