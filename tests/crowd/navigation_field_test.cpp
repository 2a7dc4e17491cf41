#include "msim/crowd/navigation_field.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include <Eigen/Geometry>

#include "msim/core/error.hpp"

namespace msim::crowd {
namespace {

Goal pointGoal(const Vec2& p, double radius = 0.3) {
  Goal g;
  g.point = p;
  g.arrivalRadius = radius;
  return g;
}

NavigationFieldOptions box(const Vec2& lo, const Vec2& hi, double h, double clearance) {
  NavigationFieldOptions o;
  o.lo = lo, o.hi = hi, o.cellSize = h, o.clearance = clearance;
  return o;
}

// Four walls enclosing [3, 7]^2 (inner side), 0.4 m thick.
std::vector<Polygon> enclosure() {
  return {rectangle({2.6, 2.6}, {7.4, 3.0}), rectangle({2.6, 7.0}, {7.4, 7.4}), rectangle({2.6, 3.0}, {3.0, 7.0}),
          rectangle({7.0, 3.0}, {7.4, 7.0})};
}

// Geodesic from a to b around a disc of radius r at o (the inflated tip of a thin wall), going
// round the side the short angle does not take: two tangents plus an arc.
double aroundDisc(const Vec2& a, const Vec2& b, const Vec2& o, double r) {
  const Vec2 u = a - o, v = b - o;
  const double around = 2 * M_PI - std::acos(u.dot(v) / (u.norm() * v.norm()));
  return std::sqrt(u.squaredNorm() - r * r) + std::sqrt(v.squaredNorm() - r * r) +
         r * (around - std::acos(r / u.norm()) - std::acos(r / v.norm()));
}

TEST(CrowdNavigationField, EmptyBoxDistanceConvergesToEuclidean) {
  const Vec2 goal(10.3, 9.7);
  double previous = 1e9;
  for (double h : {0.5, 0.25, 0.125}) {
    const NavigationField field({pointGoal(goal)}, {}, box({0, 0}, {20, 20}, h, 0.0));
    double maxError = 0;
    for (double y = 0.6; y < 19.5; y += 0.77)
      for (double x = 0.4; x < 19.5; x += 0.83) maxError = std::max(maxError, std::abs(field.distance(0, {x, y}) - (Vec2(x, y) - goal).norm()));
    std::cout << "  h = " << h << ": max |phi - euclidean| = " << maxError << " m\n";
    EXPECT_LT(maxError, 0.6 * h);
    EXPECT_LT(maxError, previous);
    previous = maxError;
  }
}

TEST(CrowdNavigationField, DirectionPointsAtAVisibleGoal) {
  const Vec2 goal(12, 7);
  const NavigationField field({pointGoal(goal)}, {}, box({0, 0}, {20, 20}, 0.25, 0.0));
  double worst = 0;
  for (const Vec2& x : {Vec2(1, 1), Vec2(18, 18), Vec2(12, 1), Vec2(3, 15), Vec2(11.2, 7.4)}) {
    const Vec2 d = field.direction(0, x);
    EXPECT_NEAR(d.norm(), 1.0, 1e-9);
    worst = std::max(worst, std::acos(std::clamp(d.dot((goal - x).normalized()), -1.0, 1.0)));
  }
  std::cout << "  worst angle to the goal: " << worst * 180 / M_PI << " deg\n";
  EXPECT_LT(worst * 180 / M_PI, 3.0);
  EXPECT_EQ(field.direction(0, goal + Vec2(0.1, 0)), Vec2::Zero());  // arrived
}

TEST(CrowdNavigationField, ThinWallDistanceIsTheGeodesicRoundTheWallEnd) {
  // Wall along x = 0 from below the domain up to y = 0; agents keep 0.3 m off it.
  const double r = 0.3, h = 0.1;
  const Vec2 a(-3, -2), b(3, -2);
  const NavigationField field({pointGoal(b)}, {rectangle({-0.01, -11}, {0.01, 0})}, box({-10, -10}, {10, 10}, h, r));
  const double exact = aroundDisc(a, b, Vec2(0, 0), r);
  const double phi = field.distance(0, a);
  std::cout << "  geodesic " << exact << " m, field " << phi << " m (" << 100 * (phi / exact - 1) << " %)\n";
  EXPECT_NEAR(phi, exact, 2 * h);  // O(h): the blocked cells staircase the inflated wall end
  // Beside the wall the direction is the tangent to the inflated wall end, never into the wall.
  for (double y : {-6.0, -3.0, -1.5}) {
    const Vec2 x(-0.45, y), toTip = -x;
    const double alpha = std::asin(r / toTip.norm());  // rotate towards -x to pass left of the tip
    const Vec2 tangent = Eigen::Rotation2D<double>(alpha) * toTip.normalized();
    const Vec2 d = field.direction(0, x);
    EXPECT_LT(std::acos(std::min(1.0, d.dot(tangent))) * 180 / M_PI, 3.0) << "y = " << y << " d = " << d.transpose();
    EXPECT_LE(d.x(), tangent.x() + 0.03) << "y = " << y;
  }
  // Agent pushed into the clearance band: still a way out, and a finite distance.
  EXPECT_TRUE(field.reachable(0, {-0.15, -3}));
  EXPECT_LT(field.direction(0, {-0.15, -3}).x(), 0.0);
}

TEST(CrowdNavigationField, EnclosedGoalIsUnreachable) {
  const NavigationField field({pointGoal({5, 5})}, enclosure(), box({0, 0}, {10, 10}, 0.25, 0.25));
  EXPECT_TRUE(std::isinf(field.distance(0, {1, 1})));
  EXPECT_EQ(field.direction(0, {1, 1}), Vec2::Zero());
  EXPECT_FALSE(field.reachable(0, {1, 1}));
  EXPECT_TRUE(field.reachable(0, {4, 6}));
  EXPECT_NEAR(field.distance(0, {4, 6}), std::sqrt(2.0), 0.1);
}

TEST(CrowdNavigationField, RegionGoal) {
  Goal g;
  g.kind = Goal::Kind::Region;
  g.regions = {rectangle({8, 0}, {10, 10})};
  const NavigationField field({g}, {}, box({0, 0}, {10, 10}, 0.25, 0.25));
  EXPECT_NEAR(field.distance(0, {2, 5}), 6.0, 0.05);
  EXPECT_GT(field.direction(0, {2, 5}).x(), 0.999);
  EXPECT_EQ(field.distance(0, {9, 5}), 0.0);
  EXPECT_EQ(field.direction(0, {9, 5}), Vec2::Zero());
}

// A set of exits (RiMEA's exit choice): one field seeded from both doors of a 10 m room; the
// distance is to the nearer door along the walkable path, so agents split where the paths are
// equal, and a wall between one of them and the agent sends it to the other.
TEST(CrowdNavigationField, ExitSetLeadsToTheNearestMember) {
  Goal exits;
  exits.kind = Goal::Kind::Region;
  exits.regions = {rectangle({0, 4}, {0.5, 6}), rectangle({9.5, 4}, {10, 6})};
  const NavigationField field({exits}, {}, box({0, 0}, {10, 10}, 0.25, 0.25));
  EXPECT_NEAR(field.distance(0, {3, 5}), 2.5, 0.05);
  EXPECT_LT(field.direction(0, {3, 5}).x(), -0.999);
  EXPECT_NEAR(field.distance(0, {8, 5}), 1.5, 0.05);
  EXPECT_GT(field.direction(0, {8, 5}).x(), 0.999);
  EXPECT_EQ(field.distance(0, {9.8, 5}), 0.0);
  // A wall at x = 2 from y = 1 to 9 hides the west door from (3, 5): the east one is nearer now.
  const NavigationField walled({exits}, {rectangle({2, 1}, {2.3, 9})}, box({0, 0}, {10, 10}, 0.25, 0.25));
  EXPECT_NEAR(walled.distance(0, {3, 5}), 6.5, 0.1);
  EXPECT_GT(walled.direction(0, {3, 5}).x(), 0.999);
}

TEST(CrowdNavigationField, ManyGoalsAreIndependent) {
  std::vector<Goal> goals;
  for (int k = 0; k < 6; ++k) goals.push_back(pointGoal({2.0 + 3 * k, 5.0}));
  const NavigationField field(goals, {}, box({0, 0}, {20, 10}, 0.25, 0.0));
  ASSERT_EQ(field.goalCount(), 6u);
  for (std::size_t k = 0; k < goals.size(); ++k) EXPECT_NEAR(field.distance(k, {10, 9}), (Vec2(10, 9) - goals[k].point).norm(), 0.6 * 0.25);
}

TEST(CrowdNavigationField, BadGoalsAreInputErrors) {
  const auto build = [](const Vec2& p) { NavigationField({pointGoal(p)}, {rectangle({4, 4}, {6, 6})}, box({0, 0}, {10, 10}, 0.25, 0.25)); };
  try {
    build({5, 5});
    FAIL() << "goal inside an obstacle accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("goals[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("obstacles[0]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(build({12, 5}), InputError);
  EXPECT_THROW(NavigationField({}, {}, box({0, 0}, {10, 10}, 0.0, 0.25)), InputError);
}

}  // namespace
}  // namespace msim::crowd
