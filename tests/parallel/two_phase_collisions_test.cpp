// Selle ch. 8.2's collision processing on a mesh split by the recursive median: the two phases
// (boundary components, then each rank's internal items) give bit for bit the velocities of one
// serial Gauss-Seidel pass in the schedule's order, on 1, 2, 4 and 8 ranks; a Jacobi pass, every
// item from the same velocities, counts impulses on shared nodes more than once (seed notes A5).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>

#include "msim/core/rng.hpp"
#include "msim/parallel/median_partition.hpp"
#include "msim/parallel/two_phase_collisions.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::fromRoot;
using testing::worldRank;
using testing::worldSize;

// A crumpled sheet of n x n nodes, and contacts between each node and the triangle of three nodes
// of a fold lying over it (4 nodes, as the cloth's point-triangle pairs): many items share nodes.
struct Contacts {
  std::vector<Vec3> x, v;
  std::vector<CollisionItem> items;
  std::vector<Vec3> normal;
};

Contacts crumpledSheet(int n) {
  Contacts c;
  Rng rng(11);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      c.x.emplace_back(i, j, 0.3 * std::sin(0.7 * i) * std::cos(0.5 * j));
      c.v.emplace_back(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1));
    }
  auto node = [&](int i, int j) { return j * n + i; };
  for (int j = 0; j + 3 < n; ++j)
    for (int i = 0; i + 3 < n; ++i) {
      // The point (i, j) against the triangle of a fold 2-3 nodes away.
      c.items.push_back({node(i, j), node(i + 2, j + 1), node(i + 3, j + 1), node(i + 2, j + 3)});
      const double a = rng.uniform(0, 6.283);
      c.normal.emplace_back(0.3 * std::cos(a), 0.3 * std::sin(a), 1.0);
      c.normal.back().normalize();
    }
  return c;
}

// The inelastic impulse of a point-triangle contact (unit masses, barycentric weights 1/3): it
// stops the point's approach to the triangle along the normal.
struct Inelastic {
  const Contacts& c;
  double* total = nullptr;  // sum of |impulse|, when given
  void operator()(int k, std::vector<Vec3>& v) const {
    const CollisionItem& it = c.items[static_cast<std::size_t>(k)];
    const double w[4] = {1.0, -1.0 / 3, -1.0 / 3, -1.0 / 3};
    const Vec3& n = c.normal[static_cast<std::size_t>(k)];
    double approach = 0.0, norm2 = 0.0;
    for (int s = 0; s < 4; ++s) {
      approach += w[s] * v[static_cast<std::size_t>(it[s])].dot(n);
      norm2 += w[s] * w[s];
    }
    if (approach >= 0.0) return;
    const double impulse = -approach / norm2;
    if (total) *total += impulse;
    for (int s = 0; s < 4; ++s) v[static_cast<std::size_t>(it[s])] += w[s] * impulse * n;
  }
};

TEST(TwoPhaseCollisions, EqualOneSerialGaussSeidelPassInTheScheduleOrder) {
  const Contacts c = crumpledSheet(48);
  const std::vector<int> owner = recursiveMedianPartition(c.x, worldSize());
  const TwoPhaseSchedule s = twoPhaseSchedule(c.items, owner, worldSize());
  std::vector<Vec3> split = c.v;
  respondTwoPhase(s, c.items, split, worldRank(), MPI_COMM_WORLD, Inelastic{c});

  std::vector<Vec3> serial = c.v;
  for (int k : s.serialOrder()) Inelastic{c}(k, serial);
  bool same = true;
  for (std::size_t i = 0; i < serial.size(); ++i) same = same && std::memcmp(serial[i].data(), split[i].data(), 3 * sizeof(double)) == 0;
  EXPECT_TRUE(same) << "rank " << worldRank();
  // Every item once: the schedule is a permutation of the items.
  std::vector<int> order = s.serialOrder();
  std::sort(order.begin(), order.end());
  EXPECT_EQ(order.size(), c.items.size());
  EXPECT_TRUE(std::adjacent_find(order.begin(), order.end()) == order.end());
  if (worldSize() > 1) {
    EXPECT_FALSE(s.components.empty()) << "no item crosses a part: the split tests nothing";
  }
  if (worldRank() == 0)
    std::printf("%zu contacts on %d ranks: %zu boundary components (%zu items), internal %zu on rank 0\n",
                c.items.size(), worldSize(), s.components.size(),
                c.items.size() - [&] { std::size_t n = 0; for (const auto& r : s.internal) n += r.size(); return n; }(),
                s.internal[0].size());
  EXPECT_TRUE(fromRoot(!::testing::Test::HasFailure()));
}

// One pass over the items in the order given: Gauss-Seidel, or Jacobi (every impulse from the
// velocities before the pass, all added up).
std::vector<Vec3> pass(const Contacts& c, const std::vector<int>& order, bool jacobi) {
  std::vector<Vec3> v = c.v;
  for (int k : order) {
    if (!jacobi) {
      Inelastic{c}(k, v);
      continue;
    }
    std::vector<Vec3> fresh = c.v;
    Inelastic{c}(k, fresh);
    for (int node : c.items[static_cast<std::size_t>(k)])
      v[static_cast<std::size_t>(node)] += fresh[static_cast<std::size_t>(node)] - c.v[static_cast<std::size_t>(node)];
  }
  return v;
}

double maxDifference(const std::vector<Vec3>& a, const std::vector<Vec3>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.size(); ++i) m = std::max(m, (a[i] - b[i]).norm());
  return m;
}

// A contact found twice (a point-triangle pair and an edge-edge pair of the same touch, or two
// ranks each reporting it): Gauss-Seidel's second visit finds the approach already stopped,
// Jacobi applies the impulse twice and the contact bounces apart.
TEST(TwoPhaseCollisions, AJacobiPassCountsSharedImpulsesMoreThanOnce) {
  const Contacts c = crumpledSheet(48);
  std::vector<int> once, twice;
  for (int k = 0; k < static_cast<int>(c.items.size()); ++k) {
    once.push_back(k);
    twice.insert(twice.end(), {k, k});
  }
  const double gaussSeidel = maxDifference(pass(c, once, false), pass(c, twice, false));
  const double jacobi = maxDifference(pass(c, once, true), pass(c, twice, true));
  if (worldRank() == 0)
    std::printf("each contact listed twice changes the velocities by %.2g (Gauss-Seidel) and %.2g (Jacobi)\n",
                gaussSeidel, jacobi);
  EXPECT_LT(gaussSeidel, 1e-12);
  EXPECT_GT(jacobi, 0.1);
}

TEST(RecursiveMedianPartition, SplitsIntoEqualCountsOfNearbyNodes) {
  const Contacts c = crumpledSheet(33);  // 1089 nodes: not a multiple of the part count
  for (int parts : {1, 2, 4, 8}) {
    const std::vector<int> owner = recursiveMedianPartition(c.x, parts);
    std::vector<int> count(static_cast<std::size_t>(parts), 0);
    std::vector<Vec3> lo(static_cast<std::size_t>(parts), Vec3::Constant(1e9)), hi(static_cast<std::size_t>(parts), Vec3::Constant(-1e9));
    for (std::size_t i = 0; i < owner.size(); ++i) {
      ++count[static_cast<std::size_t>(owner[i])];
      lo[static_cast<std::size_t>(owner[i])] = lo[static_cast<std::size_t>(owner[i])].cwiseMin(c.x[i]);
      hi[static_cast<std::size_t>(owner[i])] = hi[static_cast<std::size_t>(owner[i])].cwiseMax(c.x[i]);
    }
    const auto [fewest, most] = std::minmax_element(count.begin(), count.end());
    EXPECT_LE(*most - *fewest, 1) << parts << " parts";
    // Median cuts of a 32 x 32 sheet: each part spans about 32 / sqrt(parts) nodes per side.
    for (int p = 0; p < parts; ++p) {
      const Vec3 extent = hi[static_cast<std::size_t>(p)] - lo[static_cast<std::size_t>(p)];
      EXPECT_LE(extent[0] * extent[1], 1.3 * 32.0 * 32.0 / parts) << parts << " parts, part " << p;
    }
  }
  EXPECT_THROW(recursiveMedianPartition(c.x, 3), std::invalid_argument);
}

}  // namespace
}  // namespace msim::parallel
