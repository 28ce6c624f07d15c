#include <gtest/gtest.h>

#include <cmath>

#include "sadsplat/io/scene.h"

namespace io = sadsplat::io;

TEST(PinholeCamera, RotationOfAQuarterTurnAboutZ) {
  io::PinholeCamera c;
  c.qvec = {std::cos(M_PI / 4), 0, 0, std::sin(M_PI / 4)};
  const std::array<double, 9> expected{0, -1, 0, 1, 0, 0, 0, 0, 1};
  const std::array<double, 9> R = c.rotation();
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(R[i], expected[i], 1e-12) << i;
  c.qvec = {3 * std::cos(M_PI / 4), 0, 0, 3 * std::sin(M_PI / 4)};  // not normalised
  const std::array<double, 9> R3 = c.rotation();
  for (int i = 0; i < 9; ++i) EXPECT_NEAR(R3[i], expected[i], 1e-12) << i;
}

TEST(PinholeCamera, RotationIsOrthonormalWithDeterminantOne) {
  io::PinholeCamera c;
  c.qvec = {0.3, -0.5, 0.7, 0.2};
  const std::array<double, 9> R = c.rotation();
  for (int a = 0; a < 3; ++a) {
    for (int b = 0; b < 3; ++b) {
      double dot = 0;
      for (int k = 0; k < 3; ++k) dot += R[3 * a + k] * R[3 * b + k];
      EXPECT_NEAR(dot, a == b ? 1.0 : 0.0, 1e-12) << a << "," << b;
    }
  }
  const double det = R[0] * (R[4] * R[8] - R[5] * R[7]) - R[1] * (R[3] * R[8] - R[5] * R[6]) +
                     R[2] * (R[3] * R[7] - R[4] * R[6]);
  EXPECT_NEAR(det, 1.0, 1e-12);
}
