// The inconsistency metric and the curtailing it drives (Golas ch. 3.7-3.8; the seed notes'
// checks L6 and L7).
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>

#include <Eigen/Geometry>

#include "msim/crowd/lookahead/curtailing.hpp"
#include "msim/crowd/lookahead/inconsistency.hpp"

namespace {

using namespace msim::crowd::lookahead;
using Eigen::Vector2d;

}  // namespace

TEST(Inconsistency, VanishesForSteadyMotionAndMeasuresAlternatingAccelerations) {
  // L6: constant velocities give sigma = 0; a velocity switching by +-a along x, the deviations
  // +-a, gives C = diag(a^2, 0): sigma = a with the equations' square roots, a^2 with the trace.
  DeviationMoment steady;
  for (int k = 0; k < 10; ++k) steady.add(Vector2d::Zero());
  EXPECT_EQ(steady.sigma(), 0.0);
  EXPECT_EQ(DeviationMoment().sigma(), 0.0);
  DeviationMoment alternating;
  const double a = 1.7;
  for (int k = 0; k < 10; ++k) alternating.add(Vector2d((k % 2 == 0 ? 1.0 : -1.0) * a, 0.0));
  EXPECT_NEAR(alternating.sigma(MetricMode::SqrtEigenvalueSum), a, 1e-12);
  EXPECT_NEAR(alternating.sigma(MetricMode::Trace), a * a, 1e-12);
  EXPECT_NEAR(std::abs(alternating.directions().col(1).x()), 1.0, 1e-12) << "the principal direction is x";
}

TEST(Inconsistency, IsUnchangedByRotationAndScalesWithTheAccelerations) {
  // L6: rotating every sample leaves sigma unchanged; scaling them by s scales sigma by s (square
  // roots) or s^2 (trace). Moments of two agents add to the moment of their pooled samples.
  std::mt19937 random(5);
  std::normal_distribution<double> n(0.0, 1.0);
  for (int trial = 0; trial < 50; ++trial) {
    const double angle = 6.283 * (trial + 0.5) / 50.0, s = 0.2 + 0.1 * trial;
    const Eigen::Matrix2d rotation = Eigen::Rotation2Dd(angle).toRotationMatrix();
    DeviationMoment plain, rotated, scaled, first, second;
    for (int k = 0; k < 12; ++k) {
      const Vector2d d(n(random), 0.3 * n(random));
      plain.add(d);
      rotated.add(rotation * d);
      scaled.add(s * d);
      (k < 5 ? first : second).add(d);
    }
    first.add(second);
    EXPECT_NEAR(rotated.sigma(), plain.sigma(), 1e-12 * (1.0 + plain.sigma()));
    EXPECT_NEAR(rotated.sigma(MetricMode::Trace), plain.sigma(MetricMode::Trace), 1e-12 * (1.0 + plain.sigma(MetricMode::Trace)));
    EXPECT_NEAR(scaled.sigma(), s * plain.sigma(), 1e-12 * (1.0 + plain.sigma()));
    EXPECT_NEAR(scaled.sigma(MetricMode::Trace), s * s * plain.sigma(MetricMode::Trace), 1e-10);
    EXPECT_NEAR(first.sigma(), plain.sigma(), 1e-12);
  }
}

TEST(Curtailing, DepthFallsWithInconsistencyAndStopsShortOfObstacles) {
  // L7: sigma = 0 keeps i_max; sigma >= sigma_max gives 0; never deeper at a larger sigma; linear
  // steps at multiples of sigma_max / i_max. An obstacle D ahead allows the deepest i with
  // |v| dt_i < D.
  const int levels = 8;
  const double sigmaMax = 2.0;
  EXPECT_EQ(depthForInconsistency(0.0, sigmaMax, levels), levels);
  EXPECT_EQ(depthForInconsistency(sigmaMax, sigmaMax, levels), 0);
  EXPECT_EQ(depthForInconsistency(5.0 * sigmaMax, sigmaMax, levels), 0);
  EXPECT_EQ(depthForInconsistency(0.99 * sigmaMax / levels, sigmaMax, levels), levels);
  EXPECT_EQ(depthForInconsistency(1.01 * sigmaMax / levels, sigmaMax, levels), levels - 1);
  EXPECT_EQ(depthForInconsistency(123.0, std::numeric_limits<double>::infinity(), levels), levels) << "constant lookahead";
  int last = levels;
  for (double sigma = 0.0; sigma < 3.0; sigma += 0.001) {
    const int depth = depthForInconsistency(sigma, sigmaMax, levels);
    EXPECT_LE(depth, last);
    EXPECT_GE(depth, 0);
    last = depth;
  }
  const HorizonSchedule s{.baseStep = 0.01, .levels = levels};
  for (const double speed : {0.5, 1.3, 1.6})
    for (double clear = 0.001; clear < 3.0; clear *= 1.37) {
      int expected = 0;
      for (int i = 1; i <= levels; ++i)
        if (speed * s.horizon(i) < clear) expected = i;
      EXPECT_EQ(depthForObstacle(speed, clear, s), expected) << speed << " " << clear;
    }
  EXPECT_EQ(depthForObstacle(1.0, 0.005, s), 0);
  EXPECT_EQ(depthForObstacle(1.0, 100.0, s), levels);
}
