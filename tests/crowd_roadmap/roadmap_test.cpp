#include "msim/crowd/roadmap/roadmap.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <iostream>

#include "msim/core/error.hpp"

namespace msim::crowd {
namespace {

Goal pointGoal(const Vec2& p) {
  Goal g;
  g.point = p;
  g.arrivalRadius = 0.3;
  return g;
}

RoadmapOptions box(const Vec2& lo, const Vec2& hi) {
  RoadmapOptions o;
  o.lo = lo, o.hi = hi;
  return o;
}

TEST(CrowdRoadmap, PathRoundASquareApproximatesTheGeodesic) {
  const Polygon square = rectangle({8, 8}, {12, 12});
  const Roadmap roadmap({pointGoal({16, 10})}, {square}, box({0, 0}, {20, 20}));
  // Shortest path: over two corners of the square, (4,10) -> (8,12) -> (12,12) -> (16,10).
  const double exact = 2 * std::hypot(4.0, 2.0) + 4.0;
  const Vec2 agent(4, 10);
  const double length = roadmap.distance(0, agent);
  std::cout << "  " << roadmap.vertexCount() << " vertices, " << roadmap.edgeCount() << " edges; geodesic " << exact
            << " m, roadmap " << length << " m (+" << 100 * (length / exact - 1) << " %)\n";
  EXPECT_GE(length, exact - 1e-6);  // every roadmap path runs in free space
  EXPECT_LT(length, 1.15 * exact);
  // The bare triangulation (the seed's, no Steiner points) and a finer lattice, for the record.
  for (double spacing : {0.0, 1.0}) {
    RoadmapOptions o = box({0, 0}, {20, 20});
    o.spacing = spacing;
    const Roadmap other({pointGoal({16, 10})}, {square}, o);
    const double l = other.distance(0, agent);
    std::cout << "  spacing " << spacing << ": " << other.vertexCount() << " vertices, roadmap " << l << " m (+"
              << 100 * (l / exact - 1) << " %)\n";
    EXPECT_GE(l, exact - 1e-6);
  }
  // The preferred direction heads for a visible sub-goal past the square, not into it.
  const Roadmap::Route route = roadmap.route(0, agent);
  ASSERT_FALSE(route.path.empty());
  const Vec2 target = roadmap.vertex(route.path[route.target]);
  EXPECT_FALSE(segmentHitsPolygon(square, agent, target));
  const Vec2 d = roadmap.direction(0, agent);
  EXPECT_NEAR(d.norm(), 1.0, 1e-9);
  EXPECT_GT(d.x(), 0.0);
  EXPECT_NEAR(d.dot((target - agent).normalized()), 1.0, 1e-12);
}

TEST(CrowdRoadmap, VisibleGoalIsApproachedStraight) {
  const Vec2 goal(15, 12), agent(2, 3);
  const Roadmap roadmap({pointGoal(goal)}, {rectangle({8, 14}, {12, 18})}, box({0, 0}, {20, 20}));
  EXPECT_NEAR((roadmap.direction(0, agent) - (goal - agent).normalized()).norm(), 0.0, 1e-12);
  EXPECT_NEAR(roadmap.distance(0, agent), (goal - agent).norm(), 1e-9);
  EXPECT_EQ(roadmap.direction(0, goal + Vec2(0.1, 0)), Vec2::Zero());  // arrived
}

TEST(CrowdRoadmap, EnclosedGoalIsUnreachable) {
  const std::vector<Polygon> walls = {rectangle({2.6, 2.6}, {7.4, 3.0}), rectangle({2.6, 7.0}, {7.4, 7.4}),
                                      rectangle({2.6, 3.0}, {3.0, 7.0}), rectangle({7.0, 3.0}, {7.4, 7.0})};
  const Roadmap roadmap({pointGoal({5, 5})}, walls, box({0, 0}, {10, 10}));
  EXPECT_TRUE(std::isinf(roadmap.distance(0, {1, 1})));
  EXPECT_EQ(roadmap.direction(0, {1, 1}), Vec2::Zero());
  EXPECT_FALSE(roadmap.reachable(0, {1, 1}));
  EXPECT_TRUE(roadmap.reachable(0, {4, 6}));
}

TEST(CrowdRoadmap, RegionGoalBehindAWall) {
  Goal g;
  g.kind = Goal::Kind::Region;
  g.regions = {rectangle({16, 0}, {20, 20})};
  // Wall at x = 10 from y = 0 to y = 15: go round its upper end.
  const Roadmap roadmap({g}, {rectangle({9.8, -1}, {10.2, 15})}, box({0, 0}, {20, 20}));
  const Vec2 agent(5, 5);
  const double exact = std::hypot(4.8, 10.0) + 0.4 + 5.8;  // to the wall top, over it, across to x = 16
  const double length = roadmap.distance(0, agent);
  std::cout << "  region goal: lower bound " << exact << " m, roadmap " << length << " m\n";
  EXPECT_GE(length, exact - 1e-6);
  EXPECT_LT(length, 1.3 * exact);
  EXPECT_GT(roadmap.direction(0, agent).y(), 0.5);
  EXPECT_EQ(roadmap.distance(0, {18, 5}), 0.0);
}

TEST(CrowdRoadmap, BadInputIsRefused) {
  try {
    Roadmap({pointGoal({5, 5})}, {rectangle({4, 4}, {6, 6})}, box({0, 0}, {10, 10}));
    FAIL() << "goal inside an obstacle accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("goals[0]"), std::string::npos) << e.what();
    EXPECT_NE(std::string(e.what()).find("obstacles[0]"), std::string::npos) << e.what();
  }
  EXPECT_THROW(Roadmap({pointGoal({11, 5})}, {}, box({0, 0}, {10, 10})), InputError);
  RoadmapOptions small = box({0, 0}, {10, 10});
  small.maxVertices = 10;
  try {
    Roadmap({pointGoal({1, 1})}, {rectangle({4, 4}, {6, 6}), rectangle({7, 7}, {8, 8})}, small);
    FAIL() << "oversized roadmap accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("navigation field"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace msim::crowd
