// Agents' placement order: sortSpatially (a Hilbert curve) keeps the same points and puts
// neighbours next to each other, which is what the per-agent passes of a step rely on for
// reading memory in order.
#include "msim/crowd/agents.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cstdio>
#include <random>
#include <vector>

namespace msim::crowd {
namespace {

double meanStep(const std::vector<Vec2>& points) {
  double sum = 0.0;
  for (std::size_t i = 1; i < points.size(); ++i) sum += (points[i] - points[i - 1]).norm();
  return sum / static_cast<double>(points.size() - 1);
}

TEST(CrowdAgents, SpatialSortKeepsThePointsAndBringsNeighboursTogether) {
  std::mt19937 rng(4);
  std::uniform_real_distribution<double> u(0.0, 100.0);
  std::vector<Vec2> points(20000);
  for (Vec2& p : points) p = Vec2(u(rng), 0.5 * u(rng));
  std::vector<Vec2> sorted = points;
  sortSpatially(sorted);
  auto lexicographic = [](const Vec2& a, const Vec2& b) { return a.x() < b.x() || (a.x() == b.x() && a.y() < b.y()); };
  std::vector<Vec2> a = points, b = sorted;
  std::sort(a.begin(), a.end(), lexicographic);
  std::sort(b.begin(), b.end(), lexicographic);
  ASSERT_EQ(a, b);  // a permutation
  const double random = meanStep(points), curve = meanStep(sorted);
  std::printf("mean distance between consecutive points: %.3f m in random order, %.3f m along the curve\n", random,
              curve);
  // 20000 points on 100 x 50 m: about 0.5 m apart; a Hilbert walk steps mostly to a neighbour.
  EXPECT_LT(curve, random / 20.0);
}

}  // namespace
}  // namespace msim::crowd
