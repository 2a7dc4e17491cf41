// Inverted (containers), Translated (moving bodies) and Sampled (a mesh's distance on a grid) against their exact shapes.
#include "msim/geometry/shape_adapters.hpp"

#include <gtest/gtest.h>

#include <memory>

#include "msim/geometry/analytic_shapes.hpp"

using namespace msim;
using namespace msim::geometry;

TEST(ShapeAdapters, InvertedSwapsInsideAndOutside) {
  const auto ball = std::make_shared<Sphere<3>>(Vec3(0, 0, 0), 1.0);
  const Inverted<3> cavity(ball);
  EXPECT_DOUBLE_EQ(cavity.distance(Vec3(0.25, 0, 0)), 0.75);  // inside the ball = outside the solid
  EXPECT_DOUBLE_EQ(cavity.distance(Vec3(3, 0, 0)), -2.0);
}

TEST(ShapeAdapters, TranslatedMovesTheSurfaceAndTheBounds) {
  const auto ball = std::make_shared<Sphere<3>>(Vec3(1, 0, 0), 0.5);
  const Translated<3> moved(ball, Vec3(0, 2, 0));
  EXPECT_DOUBLE_EQ(moved.distance(Vec3(1, 2, 0)), -0.5);  // the centre moved to (1, 2, 0)
  EXPECT_DOUBLE_EQ(moved.distance(Vec3(1, 3, 0)), 0.5);
  EXPECT_DOUBLE_EQ(moved.bounds().min[1], 1.5);
  EXPECT_DOUBLE_EQ(moved.bounds().max[1], 2.5);
}

TEST(ShapeAdapters, SampledMatchesTheExactDistanceWithinTheSamplingError) {
  // A sphere's distance is smooth away from its centre: linear interpolation errs by
  // O(dx^2 / r); outside the sampled box the exact shape answers.
  const auto ball = std::make_shared<Sphere<3>>(Vec3(0, 0, 0), 1.0);
  const Sampled<3> sampled(ball, GridSpec<3>(Vec3::Constant(-2.0), 0.1, IVec3::Constant(40)));
  double worst = 0.0;
  for (double x = 0.5; x <= 1.5; x += 0.037)
    for (double y = -0.4; y <= 0.4; y += 0.053) worst = std::max(worst, std::abs(sampled.distance(Vec3(x, y, 0.11)) - ball->distance(Vec3(x, y, 0.11))));
  EXPECT_LT(worst, 0.01);
  EXPECT_DOUBLE_EQ(sampled.distance(Vec3(5, 0, 0)), 4.0);
}
