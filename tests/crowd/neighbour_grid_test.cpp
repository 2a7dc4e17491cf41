// NeighbourGrid against brute force: the exact same neighbour sets, for query radii below, at and
// above the cell size, and after rebuilds with other point counts.
#include <algorithm>
#include <random>
#include <vector>

#include <gtest/gtest.h>

#include "msim/crowd/neighbour_grid.hpp"

namespace msim::crowd {
namespace {

std::vector<Vecf<2>> randomPoints(std::size_t n, float extent, unsigned seed) {
  std::mt19937 rng(seed);
  std::uniform_real_distribution<float> u(-extent, extent);
  std::vector<Vecf<2>> p(n);
  for (auto& x : p) x = Vecf<2>(u(rng), 0.5f * u(rng));
  return p;
}

void expectSameAsBruteForce(const NeighbourGrid& grid, const std::vector<Vecf<2>>& pts, float radius) {
  std::vector<std::size_t> got, want;
  const std::size_t stride = std::max<std::size_t>(1, pts.size() / 500);
  for (std::size_t i = 0; i < pts.size(); i += stride) {
    got.clear();
    want.clear();
    grid.forEachNeighbour(i, radius, [&](std::size_t j) { got.push_back(j); });
    for (std::size_t j = 0; j < pts.size(); ++j)
      if (j != i && (pts[j] - pts[i]).squaredNorm() < radius * radius) want.push_back(j);
    std::sort(got.begin(), got.end());
    ASSERT_EQ(got, want) << "point " << i << " radius " << radius;
  }
  // forEachWithin includes the point itself when it is a query point.
  const Vecf<2> x(0.3f, -0.2f);
  got.clear();
  want.clear();
  grid.forEachWithin(x, radius, [&](std::size_t j) { got.push_back(j); });
  for (std::size_t j = 0; j < pts.size(); ++j)
    if ((pts[j] - x).squaredNorm() < radius * radius) want.push_back(j);
  std::sort(got.begin(), got.end());
  EXPECT_EQ(got, want);
}

TEST(NeighbourGrid, MatchesBruteForce) {
  NeighbourGrid grid;
  for (std::size_t n : {3000u, 200000u, 2500u}) {  // large enough for several counting blocks
    const float extent = n > 10000 ? 60.0f : 10.0f;
    const auto pts = randomPoints(n, extent, static_cast<unsigned>(n));
    grid.build(pts, 1.0f);
    ASSERT_EQ(grid.size(), n);
    for (float radius : {0.4f, 1.0f, 2.3f}) expectSameAsBruteForce(grid, pts, radius);
  }
}

TEST(NeighbourGrid, CellOrderIsStableCountingSort) {
  const auto pts = randomPoints(100000, 30.0f, 5);
  NeighbourGrid grid;
  grid.build(pts, 0.8f);
  const auto order = grid.cellOrder();
  std::vector<std::uint32_t> sorted(order.begin(), order.end());
  std::sort(sorted.begin(), sorted.end());
  for (std::uint32_t k = 0; k < sorted.size(); ++k) ASSERT_EQ(sorted[k], k);  // a permutation
  // Within one cell the input order is kept: consecutive entries in the same cell ascend.
  const float c = grid.cellSize();
  Vecf<2> lo = pts[0];
  for (const auto& p : pts) lo = lo.cwiseMin(p);
  auto cellOf = [&](std::uint32_t i) {
    const Vecf<2> rel = (pts[i] - lo) / c;
    return std::pair(std::floor(rel.y()), std::floor(rel.x()));
  };
  for (std::size_t k = 1; k < order.size(); ++k)
    if (cellOf(order[k]) == cellOf(order[k - 1])) {
      ASSERT_LT(order[k - 1], order[k]);
    }
}

TEST(NeighbourGrid, SparseFarPointsAndEmpty) {
  NeighbourGrid grid;
  grid.build(std::vector<Vecf<2>>{}, 1.0f);
  EXPECT_EQ(grid.size(), 0u);
  int count = 0;
  grid.forEachWithin(Vecf<2>::Zero(), 5.0f, [&](std::size_t) { ++count; });
  EXPECT_EQ(count, 0);
  // Two points a million cells apart must not allocate a million cells (the grid coarsens).
  const std::vector<Vecf<2>> far{Vecf<2>(0, 0), Vecf<2>(1e6f, 1e6f), Vecf<2>(0.5f, 0)};
  grid.build(far, 1.0f);
  EXPECT_GT(grid.cellSize(), 1.0f);
  std::vector<std::size_t> got;
  grid.forEachNeighbour(0, 1.0f, [&](std::size_t j) { got.push_back(j); });
  EXPECT_EQ(got, std::vector<std::size_t>{2});
}

}  // namespace
}  // namespace msim::crowd
