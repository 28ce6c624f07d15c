#include <gtest/gtest.h>

#include <random>

#include "sadsplat/common/error.h"
#include "sadsplat/pseudo_labels/few_shot_classifier.h"

namespace sp = sadsplat::pseudo_labels;

namespace {
// Three Gaussian blobs in 2-D; `group` cycles over 3 so the temperature is fitted held-out.
void blobs(int n, std::uint64_t seed, double spread, std::vector<float>& x, std::vector<int>& y,
           std::vector<int>& g) {
  std::mt19937_64 rng(seed);
  std::normal_distribution<double> noise(0.0, spread);
  const double centre[3][2] = {{0, 0}, {3, 0}, {0, 3}};
  for (int i = 0; i < n; ++i) {
    const int c = i % 3;
    x.push_back(static_cast<float>(centre[c][0] + noise(rng)));
    x.push_back(static_cast<float>(centre[c][1] + noise(rng)));
    y.push_back(c);
    g.push_back((i / 3) % 3);
  }
}
}  // namespace

TEST(FewShotClassifier, SeparatesBlobsWithRowsSummingToOne) {
  std::vector<float> x, xt;
  std::vector<int> y, g, yt, gt;
  blobs(300, 1, 0.5, x, y, g);
  blobs(300, 2, 0.5, xt, yt, gt);
  sp::FewShotClassifier c;
  c.fit(x, 2, y, g, 3);
  const std::vector<float> p = c.predictProbabilities(xt);
  ASSERT_EQ(p.size(), 900u);
  int right = 0;
  for (int i = 0; i < 300; ++i) {
    double sum = 0;
    int best = 0;
    for (int k = 0; k < 3; ++k) {
      sum += p[i * 3 + k];
      EXPECT_GE(p[i * 3 + k], 0.0f);
      if (p[i * 3 + k] > p[i * 3 + best]) best = k;
    }
    EXPECT_NEAR(sum, 1.0, 1e-5);
    right += best == yt[i];
  }
  EXPECT_GE(right, 294);  // the blobs overlap by < 1 %
}

// Calibration: with overlapping blobs, the mean top probability over held-out samples should be
// close to the held-out accuracy (within 5 points).
TEST(FewShotClassifier, ProbabilitiesAreCalibratedOnOverlappingClasses) {
  std::vector<float> x, xt;
  std::vector<int> y, g, yt, gt;
  blobs(900, 3, 1.3, x, y, g);
  blobs(3000, 4, 1.3, xt, yt, gt);
  sp::FewShotClassifier c;
  c.fit(x, 2, y, g, 3);
  const std::vector<float> p = c.predictProbabilities(xt);
  double conf = 0, acc = 0;
  for (int i = 0; i < 3000; ++i) {
    int best = 0;
    for (int k = 1; k < 3; ++k)
      if (p[i * 3 + k] > p[i * 3 + best]) best = k;
    conf += p[i * 3 + best] / 3000;
    acc += (best == yt[i]) / 3000.0;
  }
  EXPECT_GT(acc, 0.7);
  EXPECT_LT(acc, 0.95);
  EXPECT_NEAR(conf, acc, 0.05);
  EXPECT_GT(c.temperature(), 0.25);
  EXPECT_LT(c.temperature(), 8.0);
}

TEST(FewShotClassifier, BadInputIsAnError) {
  sp::FewShotClassifier c;
  EXPECT_THROW(c.predictProbabilities({1, 2}), sadsplat::Error);          // not fitted
  EXPECT_THROW(c.fit({1, 2, 3}, 2, {0, 1}, {0, 0}, 2), sadsplat::Error);  // sizes
  EXPECT_THROW(c.fit({1, 2}, 1, {0, 2}, {0, 0}, 2), sadsplat::Error);     // label out of range
  EXPECT_THROW(c.fit({1, 2}, 1, {0, 1}, {0, 0}, 1), sadsplat::Error);     // one class
}
