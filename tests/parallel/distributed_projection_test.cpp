// The distributed pressure solve (hypre PCG + PFMG on the ranks' blocks) against the serial
// projection (MG-PCG): same relative residual criterion, and the projected velocity equal within
// what the tolerance leaves, with a solid sphere inside, open and closed domains, on every rank
// count the test runs with.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/numerics/pressure/face_fractions.hpp"
#include "msim/numerics/pressure/projection.hpp"
#include "msim/parallel/distributed_projection.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using numerics::DomainSide;
using numerics::DomainSides;
using testing::fromRoot;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kProjectionGrid(Vec<3>::Zero(), 1.0 / 32, IVec<3>(32, 28, 24));
constexpr double kTolerance = 1e-6;

// A velocity with divergence everywhere: the projection has work on every block.
MacGrid<3> divergentVelocity() {
  MacGrid<3> u(kProjectionGrid);
  for (int a = 0; a < 3; ++a) {
    Grid<float, 3>& c = u.component(a);
    for (std::size_t i = 0; i < c.count(); ++i) {
      const Vec<3> x = c.position(c.coord(i));
      const double v[3] = {std::sin(5 * x[1]) + x[0] * x[0], std::cos(3 * x[2]) * x[0] + 0.5,
                           0.3 * std::sin(7 * x[0] * x[1]) + x[2]};
      c[i] = static_cast<float>(v[a]);
    }
  }
  return u;
}

MacGrid<3> sphereOpenFractions() {
  return numerics::openFaceFractionsFromSdf<3>(kProjectionGrid, [](const Vec<3>& x) {
    return (x - Vec<3>(0.45, 0.42, 0.37)).norm() - 0.17;  // solid inside
  });
}

DomainSides<3> openTop() {
  DomainSides<3> s;
  s.side[1][1] = DomainSide::Open;
  return s;
}

struct Case {
  const char* name;
  DomainSides<3> sides;
};

class DistributedProjectionTest : public ::testing::TestWithParam<int> {};

TEST_P(DistributedProjectionTest, MatchesTheSerialProjectionWithinTheTolerance) {
  const Case c = GetParam() == 0 ? Case{"open top", openTop()} : Case{"closed box", DomainSides<3>::allWalls()};
  const MacGrid<3> open = sphereOpenFractions();
  const double dt = 0.02, density = 1.3;
  numerics::PcgSettings pcg;
  pcg.tolerance = kTolerance;
  pcg.maxIterations = 400;

  MacGrid<3> serial = divergentVelocity();
  numerics::PcgStats serialStats;
  if (worldRank() == 0) {
    numerics::ProjectionSettings settings;
    settings.pcg = pcg;
    numerics::PressureProjection<3> projection(kProjectionGrid, c.sides, settings);
    projection.setSolids(open);
    serialStats = projection.project(serial, dt, density);
  }

  const GridBlock<3> block(kProjectionGrid, BlockDecomposition<3>(kProjectionGrid.res, worldSize(), 2, "test"), worldRank(), 1);
  MacGrid<3> local = localPart(divergentVelocity(), block);
  DistributedProjection projection(block, c.sides, pcg, MPI_COMM_WORLD);
  projection.setOpenFractions(localPart(open, block));
  Grid<float, 3> pressure(block.localSpec());
  const SplitSolveStats stats = projection.project(local, pressure, dt, density);
  const MacGrid<3> split = gatherToRoot(local, block, MPI_COMM_WORLD);

  bool ok = true;
  if (worldRank() == 0) {
    EXPECT_TRUE(serialStats.converged) << c.name;
    EXPECT_TRUE(stats.converged) << c.name << ": " << stats.relativeResidual;
    EXPECT_LE(stats.relativeResidual, kTolerance) << c.name;
    // The two solutions differ by what each solver's residual leaves: the velocity change is
    // grad p^, O(1) here, and both residuals are 1e-6 of the right-hand side.
    double worst = 0.0, scale = 0.0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < serial.component(a).count(); ++i) {
        worst = std::max(worst, double(std::abs(split.component(a)[i] - serial.component(a)[i])));
        scale = std::max(scale, double(std::abs(serial.component(a)[i])));
      }
    EXPECT_LT(worst, 1e-4 * scale) << c.name << " on " << worldSize() << " ranks: " << stats.iterations
                                   << " hypre iterations, serial " << serialStats.iterations;
    ok = !::testing::Test::HasFailure();
    std::printf("%s, %d ranks: max |u - u_serial| = %.2e (max |u| %.2f); hypre %d iterations, residual %.1e; serial %d, %.1e\n",
                c.name, worldSize(), worst, scale, stats.iterations, stats.relativeResidual, serialStats.iterations,
                serialStats.relativeResidual);
  }
  fromRoot(ok);
}

INSTANTIATE_TEST_SUITE_P(Domains, DistributedProjectionTest, ::testing::Values(0, 1));

// A liquid's pressure solve (the building block of split liquids): a pool with a drop above it in
// a closed box, the ghost-fluid free surface, against the serial projection's setFreeSurface.
TEST(DistributedProjection, FreeSurfaceMatchesTheSerialProjection) {
  auto liquidPhi = [](const GridSpec<3>& spec) {
    Grid<float, 3> phi(spec);
    for (std::size_t i = 0; i < phi.count(); ++i) {
      const Vec<3> x = phi.position(phi.coord(i));
      const double pool = x[1] - 0.31 - 0.03 * std::sin(9 * x[0]), drop = (x - Vec<3>(0.5, 0.62, 0.41)).norm() - 0.12;
      phi[i] = static_cast<float>(std::min(pool, drop));
    }
    return phi;
  };
  const double dt = 0.02, density = 1000.0;
  numerics::PcgSettings pcg;
  pcg.tolerance = kTolerance;
  pcg.maxIterations = 400;
  MacGrid<3> serial = divergentVelocity();
  if (worldRank() == 0) {
    numerics::ProjectionSettings settings;
    settings.pcg = pcg;
    numerics::PressureProjection<3> projection(kProjectionGrid, DomainSides<3>::allWalls(), settings);
    projection.setFreeSurface(liquidPhi(kProjectionGrid));
    EXPECT_TRUE(projection.project(serial, dt, density).converged);
  }
  const GridBlock<3> block(kProjectionGrid, BlockDecomposition<3>(kProjectionGrid.res, worldSize(), 2, "test"), worldRank(), 1);
  MacGrid<3> local = localPart(divergentVelocity(), block);
  DistributedProjection projection(block, DomainSides<3>::allWalls(), pcg, MPI_COMM_WORLD);
  projection.setFreeSurface(liquidPhi(block.localSpec()));
  Grid<float, 3> pressure(block.localSpec());
  const SplitSolveStats stats = projection.project(local, pressure, dt, density);
  const MacGrid<3> split = gatherToRoot(local, block, MPI_COMM_WORLD);
  if (worldRank() == 0) {
    EXPECT_TRUE(stats.converged) << stats.relativeResidual;
    double worst = 0.0, scale = 0.0;
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < serial.component(a).count(); ++i) {
        worst = std::max(worst, double(std::abs(split.component(a)[i] - serial.component(a)[i])));
        scale = std::max(scale, double(std::abs(serial.component(a)[i])));
      }
    std::printf("free surface, %d ranks: max |u - u_serial| = %.2e (max |u| %.2f); hypre %d iterations, residual %.1e\n",
                worldSize(), worst, scale, stats.iterations, stats.relativeResidual);
    EXPECT_LT(worst, 1e-4 * scale);
  }
  fromRoot(!::testing::Test::HasFailure());
}

}  // namespace
}  // namespace msim::parallel
