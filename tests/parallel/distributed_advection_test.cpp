// Selle ch. 8.1 / seed notes A5: advection on a grid split among ranks, with ghost layers filled
// by MPI, equals the serial run bit for bit: semi-Lagrangian, MacCormack and BFECC, on every
// block lattice the rank count allows (2x2x2 at 8 ranks: blocks that touch at a corner only).
#include <gtest/gtest.h>

#include <cmath>
#include <cstring>
#include <vector>

#include "msim/numerics/advection/advector.hpp"
#include "msim/parallel/ghost_exchange.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using numerics::AdvectionScheme;
using numerics::AdvectionSettings;
using numerics::Advector;
using testing::fromRoot;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kAdvectionGrid(Vec<3>(-0.5, -0.4, -0.3), 1.0 / 34, IVec<3>(34, 27, 21));
constexpr double kCfl = 0.9;
constexpr int kAdvectionSteps = 6;

// A swirl about a tilted axis plus a shear: divergent and varying on every axis, so feet land
// in every direction and off the lattice. Scaled so the fastest face moves kCfl cells per step.
MacGrid<3> initialVelocity(double& dt) {
  MacGrid<3> u(kAdvectionGrid);
  double fastest = 0.0;
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& c = u.component(a);
    for (std::size_t i = 0; i < c.count(); ++i) {
      const Vec<3> x = c.position(c.coord(i));
      const Vec<3> v(-x[1] + 0.3 * x[2] * x[2], x[0] + 0.2 * std::sin(4 * x[2]), 0.4 * x[0] * x[1] + 0.1);
      c[i] = static_cast<float>(v[a]);
      fastest = std::max(fastest, std::abs(double(c[i])));
    }
  }
  dt = kCfl * kAdvectionGrid.dx / fastest;
  return u;
}

// A smooth blob with a sharp-edged box inside: the limiter acts at the edges.
Grid<float, 3> initialDensity() {
  Grid<float, 3> d(kAdvectionGrid);
  for (std::size_t i = 0; i < d.count(); ++i) {
    const Vec<3> x = d.position(d.coord(i));
    const double blob = std::exp(-12.0 * (x - Vec<3>(0.1, 0.0, 0.0)).squaredNorm());
    const bool box = std::abs(x[0] + 0.2) < 0.1 && std::abs(x[1] - 0.1) < 0.12 && std::abs(x[2]) < 0.08;
    d[i] = static_cast<float>(blob + (box ? 1.0 : 0.0));
  }
  return d;
}

AdvectionSettings settingsFor(AdvectionScheme scheme) {
  AdvectionSettings s;
  s.scheme = scheme;
  return s;
}

struct Fields {
  Grid<float, 3> density;
  MacGrid<3> velocity;
};

// kAdvectionSteps of: density advected by the velocity, then the velocity by itself.
Fields serialRun(AdvectionScheme scheme) {
  double dt = 0.0;
  Fields f{initialDensity(), initialVelocity(dt)};
  Advector<float, 3> advector(kAdvectionGrid, settingsFor(scheme));
  for (int step = 0; step < kAdvectionSteps; ++step) {
    advector.advect(f.density, f.velocity, dt);
    advector.advect(f.velocity, f.velocity, dt);
  }
  return f;
}

// The same on this rank's block of `lattice`, ghosts exchanged before every advection; the
// result gathered on rank 0.
Fields distributedRun(AdvectionScheme scheme, const IVec<3>& lattice, int ghost) {
  double dt = 0.0;
  const Fields initial{initialDensity(), initialVelocity(dt)};
  const GridBlock<3> block(kAdvectionGrid, BlockDecomposition<3>(kAdvectionGrid.res, lattice, 1, "test"), worldRank(), ghost);
  Fields local{localPart(initial.density, block), localPart(initial.velocity, block)};
  GhostExchange<float, 3> densityGhosts(block, IVec<3>::Zero(), MPI_COMM_WORLD);
  MacGhostExchange<3> velocityGhosts(block, MPI_COMM_WORLD);
  Advector<float, 3> advector(block.localSpec(), settingsFor(scheme), numerics::allClamped<3>(), block.placement());
  for (int step = 0; step < kAdvectionSteps; ++step) {
    densityGhosts.exchange(local.density);
    velocityGhosts.exchange(local.velocity);
    advector.advect(local.density, local.velocity, dt);
    velocityGhosts.exchange(local.velocity);
    advector.advect(local.velocity, local.velocity, dt);
  }
  return {gatherToRoot(local.density, block, MPI_COMM_WORLD), gatherToRoot(local.velocity, block, MPI_COMM_WORLD)};
}

bool bitwiseEqual(const Grid<float, 3>& a, const Grid<float, 3>& b) {
  return a.size() == b.size() && std::memcmp(a.data().data(), b.data().data(), a.count() * sizeof(float)) == 0;
}

std::size_t samplesDiffering(const Fields& a, const Fields& b) {
  std::size_t n = 0;
  auto count = [&](const Grid<float, 3>& x, const Grid<float, 3>& y) {
    for (std::size_t i = 0; i < x.count(); ++i) n += std::memcmp(&x[i], &y[i], sizeof(float)) != 0;
  };
  count(a.density, b.density);
  for (int c = 0; c < 3; ++c) count(a.velocity.component(c), b.velocity.component(c));
  return n;
}

// Every lattice p0 x p1 x p2 with product `ranks` that leaves blocks of at least 1 cell.
std::vector<IVec<3>> latticesFor(int ranks) {
  std::vector<IVec<3>> out;
  for (int p = 1; p <= ranks; ++p)
    for (int q = 1; p * q <= ranks; ++q)
      if (ranks % (p * q) == 0) out.emplace_back(p, q, ranks / (p * q));
  return out;
}

class DistributedAdvection : public ::testing::TestWithParam<AdvectionScheme> {};

TEST_P(DistributedAdvection, EqualsTheSerialRunBitForBitOnEveryLattice) {
  const AdvectionScheme scheme = GetParam();
  const Fields serial = worldRank() == 0 ? serialRun(scheme) : Fields{};
  const int ghost = advectionGhostLayers(settingsFor(scheme), kCfl);
  for (const IVec<3>& lattice : latticesFor(worldSize())) {
    const Fields split = distributedRun(scheme, lattice, ghost);
    bool same = true;
    if (worldRank() == 0) {
      same = bitwiseEqual(split.density, serial.density);
      for (int a = 0; a < 3; ++a) same = same && bitwiseEqual(split.velocity.component(a), serial.velocity.component(a));
      if (!same)
        ADD_FAILURE() << "lattice " << lattice.transpose() << ": " << samplesDiffering(split, serial)
                      << " samples differ from the serial run";
    }
    fromRoot(same);
  }
}

INSTANTIATE_TEST_SUITE_P(Schemes, DistributedAdvection,
                         ::testing::Values(AdvectionScheme::FirstOrder, AdvectionScheme::MacCormack,
                                           AdvectionScheme::BFECC));

// The negative control: MacCormack with one ghost layer (a single stage's reach) reads clamped
// samples in its second stage, and the split run departs from the serial one.
TEST(DistributedAdvection, TooFewGhostLayersDepartFromTheSerialRun) {
  if (worldSize() == 1) GTEST_SKIP() << "one rank has no ghosts from neighbours";
  const Fields serial = worldRank() == 0 ? serialRun(AdvectionScheme::MacCormack) : Fields{};
  const int narrow = 1;
  ASSERT_LT(narrow, advectionGhostLayers(settingsFor(AdvectionScheme::MacCormack), kCfl));
  const Fields split = distributedRun(AdvectionScheme::MacCormack, latticesFor(worldSize()).back(), narrow);
  if (worldRank() == 0) {
    EXPECT_GT(samplesDiffering(split, serial), 0u);
  }
}

}  // namespace
}  // namespace msim::parallel
