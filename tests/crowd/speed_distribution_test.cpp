// Walking-speed distributions of a group: their samples' moments and bounds, and bad input.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <vector>

#include "msim/crowd/speed_distribution.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

struct Moments {
  double mean = 0.0, sd = 0.0, min = INFINITY, max = -INFINITY;
};

Moments moments(const SpeedDistribution& d, int n) {
  Rng rng(7);
  std::vector<double> v(static_cast<std::size_t>(n));
  for (double& x : v) x = d.sample(rng);
  Moments m;
  for (double x : v) m.mean += x / n, m.min = std::min(m.min, x), m.max = std::max(m.max, x);
  for (double x : v) m.sd += (x - m.mean) * (x - m.mean) / (n - 1);
  m.sd = std::sqrt(m.sd);
  return m;
}

std::string messageOf(const SpeedDistribution& d) {
  try {
    d.validate("groups[2]");
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(accepted)";
}

}  // namespace

TEST(SpeedDistribution, UniformCoversItsRangeWithTheRightMoments) {
  SpeedDistribution d;
  d.kind = SpeedDistribution::Kind::Uniform;
  d.min = 0.8, d.max = 1.6;
  const Moments m = moments(d, 20000);
  EXPECT_NEAR(m.mean, 1.2, 0.01);
  EXPECT_NEAR(m.sd, 0.8 / std::sqrt(12.0), 0.005);
  EXPECT_GE(m.min, 0.8);
  EXPECT_LE(m.max, 1.6);
  EXPECT_LT(m.min, 0.81);
  EXPECT_GT(m.max, 1.59);
}

TEST(SpeedDistribution, TruncatedNormalKeepsItsMeanAndBounds) {
  // Weidmann's adults: 1.34 m/s, sd 0.26, truncated symmetrically at +-2.5 sd (the truncated sd
  // is 0.947 of the untruncated one).
  SpeedDistribution d;
  d.kind = SpeedDistribution::Kind::Normal;
  d.mean = 1.34, d.sd = 0.26, d.min = 1.34 - 0.65, d.max = 1.34 + 0.65;
  const Moments m = moments(d, 40000);
  EXPECT_NEAR(m.mean, 1.34, 0.005);
  EXPECT_NEAR(m.sd, 0.947 * 0.26, 0.005);
  EXPECT_GE(m.min, d.min);
  EXPECT_LE(m.max, d.max);
}

TEST(SpeedDistribution, FixedIsTheMean) {
  SpeedDistribution d;
  d.mean = 1.1;
  EXPECT_EQ(moments(d, 10).sd, 0.0);
  EXPECT_EQ(moments(d, 10).mean, 1.1);
}

TEST(SpeedDistribution, ZeroOrNegativeSpeedsAreRefusedNamingTheKey) {
  SpeedDistribution uniform;
  uniform.kind = SpeedDistribution::Kind::Uniform;
  uniform.min = 0.0, uniform.max = 1.5;
  EXPECT_NE(messageOf(uniform).find("groups[2].speed_min"), std::string::npos) << messageOf(uniform);
  uniform.min = 1.6;
  EXPECT_NE(messageOf(uniform).find("groups[2].speed_max"), std::string::npos) << messageOf(uniform);
  SpeedDistribution normal;
  normal.kind = SpeedDistribution::Kind::Normal;
  normal.mean = 1.3, normal.sd = 0.3, normal.min = -0.2, normal.max = 2.0;
  EXPECT_NE(messageOf(normal).find("groups[2].speed_min"), std::string::npos) << messageOf(normal);
  normal.min = 0.5, normal.sd = 0.0;
  EXPECT_NE(messageOf(normal).find("groups[2].speed_sd"), std::string::npos) << messageOf(normal);
  normal.sd = 0.3, normal.mean = 2.5;
  EXPECT_NE(messageOf(normal).find("groups[2].max_speed"), std::string::npos) << messageOf(normal);
  normal.mean = 1.3;
  EXPECT_EQ(messageOf(normal), "(accepted)");
}
