// The hybrid's blend weights (Golas ch. 3.9, eqs. 3.12-3.13; the seed notes' check L8).
#include <gtest/gtest.h>

#include "msim/crowd/lookahead/blending.hpp"

using namespace msim::crowd::lookahead;

TEST(LookaheadBlending, WeightsAtTheSeedsThresholds) {
  const BlendThresholds t;  // rho_cmin 2, rho_dmax 4; c_1 1, c_2 2
  EXPECT_EQ(densityWeight(1.9, t), 0.0);
  EXPECT_DOUBLE_EQ(densityWeight(3.0, t), 0.5);
  EXPECT_EQ(densityWeight(4.1, t), 1.0);
  const double vbar = 1.2;
  EXPECT_EQ(varianceWeight(0.5 * vbar, vbar, t), 1.0);
  EXPECT_EQ(varianceWeight(vbar, vbar, t), 1.0);
  EXPECT_DOUBLE_EQ(varianceWeight(1.5 * vbar, vbar, t), 0.5);
  EXPECT_EQ(varianceWeight(2.0 * vbar, vbar, t), 0.0);
  EXPECT_EQ(varianceWeight(3.0 * vbar, vbar, t), 0.0);
  EXPECT_DOUBLE_EQ(blendWeight(3.0, 1.5 * vbar, vbar, t), 0.25);
  // A crowd standing still: uniform if nobody moves, disordered if some do.
  EXPECT_EQ(varianceWeight(0.01, 0.0, t), 1.0);
  EXPECT_EQ(varianceWeight(0.3, 0.01, t), 0.0);
}
