// Pressure projection: divergence removal, no-leak solid faces, moving obstacles, preconditioner
// agreement, multigrid scaling and second-order convergence to a manufactured solution.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"
#include "msim/numerics/pressure/projection.hpp"
#include "msim/numerics/pressure/vector_ops.hpp"
#include "../unit_box.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

using msim::test::unitBox;

template <int D>
MacGrid<D> randomVelocity(const GridSpec<D>& spec, std::uint64_t seed) {
  Rng rng(seed);
  MacGrid<D> u(spec);
  for (int a = 0; a < D; ++a)
    for (float& v : u.component(a).data()) v = static_cast<float>(rng.uniform(-1.0, 1.0));
  return u;
}

// A ball off the box centre, so the flow is not symmetric.
template <int D>
MacGrid<D> ballFractions(const GridSpec<D>& spec, double radius) {
  Vec<D> centre = Vec<D>::Constant(0.45);
  centre[0] = 0.55;
  return openFaceFractionsFromSdf<D>(spec, [&](const Vec<D>& x) { return (x - centre).norm() - radius; });
}

template <int D>
double maxAbs(const Grid<float, D>& g) {
  return numerics::maxAbs(g.data());
}

ProjectionSettings settingsFor(PressurePreconditioner p, double tolerance) {
  ProjectionSettings s;
  s.preconditioner = p;
  s.pcg.tolerance = tolerance;
  s.pcg.maxIterations = 2000;
  return s;
}

class ClosedBoxWithBall : public ::testing::TestWithParam<PressurePreconditioner> {};

}  // namespace

TEST_P(ClosedBoxWithBall, RemovesDivergenceAndNothingCrossesSolidFaces) {
  constexpr double kTol = 1e-5;
  const GridSpec<3> spec = unitBox<3>(32);
  PressureProjection<3> proj(spec, DomainSides<3>::allWalls(), settingsFor(GetParam(), kTol));
  proj.setSolids(ballFractions<3>(spec, 0.2));
  EXPECT_EQ(proj.floatingRegions().count(), 1u);  // a closed box: pressure defined up to a constant

  MacGrid<3> u = randomVelocity<3>(spec, 1);
  Grid<float, 3> div(spec);
  proj.divergence(u, div);
  const double before = maxAbs(div);
  const PcgStats stats = proj.project(u, 0.01, 1000.0);
  proj.divergence(u, div);
  const double after = maxAbs(div);
  fmt::print("closed box 32^3 + ball: {} iterations, relative residual {:.2e}, max|div| {:.3g} -> {:.3g}\n",
             stats.iterations, stats.relativeResidual, before, after);
  EXPECT_TRUE(stats.converged);
  EXPECT_LE(stats.relativeResidual, kTol);
  EXPECT_LE(after, 1.5 * kTol * before);  // the residual is the divergence, up to float rounding

  // Closed faces (inside the ball, on the walls) carry the solid's velocity: zero.
  int closed = 0, partial = 0;
  for (int a = 0; a < 3; ++a) {
    const auto& w = proj.faceWeights().component(a);
    for (std::size_t i = 0; i < w.count(); ++i) {
      if (w[i] == 0.0f) {
        ++closed;
        ASSERT_EQ(u.component(a)[i], 0.0f);
      } else if (w[i] < 1.0f) {
        ++partial;
      }
    }
  }
  EXPECT_GT(partial, 100);  // the ball is resolved by fractions, not a staircase
  EXPECT_GT(closed, 6 * 32 * 32);
  // Cells inside the ball have no pressure.
  EXPECT_EQ(proj.pressure()(IVec3(17, 14, 14)), 0.0f);
}

INSTANTIATE_TEST_SUITE_P(Preconditioners, ClosedBoxWithBall,
                         ::testing::Values(PressurePreconditioner::Multigrid, PressurePreconditioner::Mic0));

TEST(Projection, MovingBallInClosedBoxConservesVolumeThroughEveryPlane) {
  // u* = 0 and a ball moving with velocity V: the fluid must flow round it so that the volume
  // flux through every plane x = const (fluid part w u plus the ball's part (1 - w) V) is zero.
  const int n = 32;
  const GridSpec<3> spec = unitBox<3>(n);
  PressureProjection<3> proj(spec, DomainSides<3>::allWalls(), settingsFor(PressurePreconditioner::Multigrid, 1e-6));
  const double r = 0.2;
  proj.setSolids(ballFractions<3>(spec, r));
  MacGrid<3> solid(spec);
  solid.component(0).fill(1.0f);
  proj.setSolidVelocity(solid);
  MacGrid<3> u(spec);
  const PcgStats stats = proj.project(u, 0.01, 1.0);
  EXPECT_TRUE(stats.converged);

  const auto& w = proj.faceWeights().component(0);
  double worst = 0.0, fluidBackflow = 0.0;
  for (int i = 1; i < n; ++i) {
    double flux = 0.0;
    for (int k = 0; k < n; ++k)
      for (int j = 0; j < n; ++j) {
        const IVec3 f(i, j, k);
        flux += (w(f) * u.component(0)(f) + (1.0 - w(f)) * 1.0) * spec.dx * spec.dx;
        if (i == 17) fluidBackflow += w(f) * u.component(0)(f) * spec.dx * spec.dx;
      }
    worst = std::max(worst, std::abs(flux));
  }
  const double displaced = std::numbers::pi * r * r;  // volume flux the ball pushes through its midplane
  fmt::print("moving ball: {} iterations, worst plane flux {:.2e} (ball pushes {:.3f})\n", stats.iterations, worst,
             displaced);
  EXPECT_LT(worst, 1e-4 * displaced);
  EXPECT_NEAR(fluidBackflow, -displaced, 0.05 * displaced);  // the fluid returns what the ball pushes
}

TEST(Projection, WarmStartFromProjectedFieldNeedsNoIterations) {
  const GridSpec<2> spec = unitBox<2>(64);
  PressureProjection<2> proj(spec, DomainSides<2>::allWalls(), settingsFor(PressurePreconditioner::Multigrid, 1e-5));
  proj.setSolids(ballFractions<2>(spec, 0.2));
  MacGrid<2> u = randomVelocity<2>(spec, 3);
  EXPECT_GT(proj.project(u, 0.01, 1.0).iterations, 0);
  // Same u* again: the stored pressure already solves it.
  MacGrid<2> again = randomVelocity<2>(spec, 3);
  EXPECT_EQ(proj.project(again, 0.01, 1.0).iterations, 0);
}

template <int D>
void expectPreconditionersAgree(int n) {
  const GridSpec<D> spec = unitBox<D>(n);
  DomainSides<D> sides = DomainSides<D>::allWalls();
  sides.side[D - 1][1] = DomainSide::Open;  // one open side: a mix of Neumann and Dirichlet
  Grid<float, D> pressure[2];
  int k = 0;
  for (auto p : {PressurePreconditioner::Multigrid, PressurePreconditioner::Mic0}) {
    PressureProjection<D> proj(spec, sides, settingsFor(p, 1e-6));
    proj.setSolids(ballFractions<D>(spec, 0.2));
    MacGrid<D> u = randomVelocity<D>(spec, 5);
    const PcgStats stats = proj.project(u, 0.1, 1.0);
    EXPECT_TRUE(stats.converged);
    fmt::print("{}D {}^{}: {} iterations {}\n", D, n, D, p == PressurePreconditioner::Mic0 ? "MIC(0)-PCG" : "MG-PCG",
               stats.iterations);
    pressure[k++] = proj.pressure();
  }
  double diff = 0.0;
  for (std::size_t i = 0; i < pressure[0].count(); ++i) diff = std::max(diff, double(std::abs(pressure[0][i] - pressure[1][i])));
  const double scale = maxAbs(pressure[0]);
  fmt::print("  max |p_MG - p_MIC| / max |p| = {:.2e}\n", diff / scale);
  EXPECT_GT(scale, 0.0);
  EXPECT_LT(diff, 1e-3 * scale);
}

TEST(Projection, MicAndMultigridGiveTheSamePressure2D) { expectPreconditionersAgree<2>(128); }
TEST(Projection, MicAndMultigridGiveTheSamePressure3D) { expectPreconditionersAgree<3>(32); }

TEST(Multigrid, IterationCountsAreFlatUnderRefinement) {
  // Issue #3: flat within 2 from 32^3 to 128^3. The tolerance is 1e-5, the default of the smoke
  // solver: at 1e-6 the float residual of 2M cells nears the tolerance at 128^3 and costs 3 more
  // iterations there (6 / 6 / 9) without the multigrid getting any worse.
  std::vector<int> iterations;
  for (int n : {32, 64, 128}) {
    const GridSpec<3> spec = unitBox<3>(n);
    PressureProjection<3> proj(spec, DomainSides<3>::allWalls(), settingsFor(PressurePreconditioner::Multigrid, 1e-5));
    proj.setSolids(ballFractions<3>(spec, 0.2));
    MacGrid<3> u = randomVelocity<3>(spec, 11);
    const PcgStats stats = proj.project(u, 0.1, 1.0);
    EXPECT_TRUE(stats.converged);
    fmt::print("MG-PCG {}^3 closed box + ball, tol 1e-5: {} iterations, {} levels\n", n, stats.iterations,
               proj.multigridLevels());
    iterations.push_back(stats.iterations);
  }
  const auto [fewest, most] = std::minmax_element(iterations.begin(), iterations.end());
  EXPECT_LE(*most - *fewest, 2);
}

TEST(Multigrid, OddCellCountsCoarsenAndConvergeAsEvenOnes) {
  // A grid with an odd cell count on some axis (85 x 128 x 85: the 3D plume at resolution 128)
  // keeps coarsening, its last coarse cell covering one fine cell; the iterations stay those of
  // the even grid next to it (a single level of 30 sweep pairs took 32-40 there).
  std::vector<int> iterations;
  for (const IVec<3>& res : {IVec<3>(42, 64, 42), IVec<3>(43, 64, 43), IVec<3>(45, 63, 41)}) {
    const GridSpec<3> spec(Vec<3>::Zero(), 1.0 / 64, res);
    DomainSides<3> sides;
    sides.side[1][1] = DomainSide::Open;
    PressureProjection<3> proj(spec, sides, settingsFor(PressurePreconditioner::Multigrid, 1e-5));
    proj.setSolids(ballFractions<3>(spec, 0.15));
    MacGrid<3> u = randomVelocity<3>(spec, 5);
    const PcgStats stats = proj.project(u, 0.1, 1.0);
    EXPECT_TRUE(stats.converged);
    EXPECT_GE(proj.multigridLevels(), 4) << res.transpose();
    fmt::print("MG-PCG {} x {} x {}, open top + ball: {} iterations, {} levels\n", res[0], res[1], res[2],
               stats.iterations, proj.multigridLevels());
    iterations.push_back(stats.iterations);
  }
  EXPECT_LE(iterations[1], iterations[0] + 2);
  EXPECT_LE(iterations[2], iterations[0] + 2);
}

TEST(Projection, ManufacturedDirichletSolutionConvergesAtSecondOrder) {
  // p = sin(pi x) sin(pi y) on [0,1]^2 with p = 0 on the boundary. The grid is laid out so the
  // ghost cell centres sit on x, y = 0 and 1 (dx = 1/(n+1)), where the Dirichlet value is taken.
  // With u* = (dt/rho) grad p sampled exactly on the faces, the projection must recover p.
  const double dt = 0.5, rho = 2.0;
  const double pi = std::numbers::pi;
  double errors[3];
  int k = 0;
  for (int n : {32, 64, 128}) {
    const double dx = 1.0 / (n + 1);
    const GridSpec<2> spec(Vec2::Constant(0.5 * dx), dx, IVec2::Constant(n));
    PressureProjection<2> proj(spec, DomainSides<2>::allOpen(), settingsFor(PressurePreconditioner::Multigrid, 1e-7));
    MacGrid<2> u(spec);
    for (int a = 0; a < 2; ++a) {
      auto& c = u.component(a);
      for (std::size_t i = 0; i < c.count(); ++i) {
        const Vec2 x = c.position(c.coord(i));
        const double g = a == 0 ? pi * std::cos(pi * x[0]) * std::sin(pi * x[1]) : pi * std::sin(pi * x[0]) * std::cos(pi * x[1]);
        c[i] = static_cast<float>(dt / rho * g);
      }
    }
    EXPECT_TRUE(proj.project(u, dt, rho).converged);
    double err = 0.0;
    const auto& p = proj.pressure();
    for (std::size_t i = 0; i < p.count(); ++i) {
      const Vec2 x = spec.cellCenter(p.coord(i));
      err = std::max(err, std::abs(p[i] - std::sin(pi * x[0]) * std::sin(pi * x[1])));
    }
    errors[k++] = err;
  }
  const double order1 = std::log2(errors[0] / errors[1]), order2 = std::log2(errors[1] / errors[2]);
  fmt::print("manufactured Dirichlet: max errors {:.2e} {:.2e} {:.2e}, orders {:.2f} {:.2f}\n", errors[0], errors[1],
             errors[2], order1, order2);
  EXPECT_LT(errors[0], 1e-3);
  EXPECT_GT(order1, 1.8);
  EXPECT_GT(order2, 1.8);
}

TEST(Projection, InflowAndOutflowWallsCarryTheirFluxPastAnObstacle) {
  // Selle ch. 2.9's wind tunnel: every side a wall, u = 1 on the left and right walls, a disc in
  // the way. Every vertical line must then carry the tunnel's volume flux (height x 1) and the
  // flow must speed up beside the disc to do so.
  constexpr double kTol = 1e-5;
  const GridSpec<2> spec(Vec2::Zero(), 0.01, IVec2(300, 100));
  PressureProjection<2> proj(spec, DomainSides<2>::allWalls(), settingsFor(PressurePreconditioner::Multigrid, kTol));
  proj.setSolids(openFaceFractionsFromSdf<2>(spec, [](const Vec2& x) { return (x - Vec2(0.5, 0.5)).norm() - 0.125; }));
  proj.setWallNormalVelocity(0, 0, 1.0);
  proj.setWallNormalVelocity(0, 1, 1.0);
  // Start from the free stream, as a wind-tunnel run does: from rest the float pressure would have
  // to span the whole tunnel and its round-off alone leaves a divergence of ~2e-4 |u| / dx.
  MacGrid<2> u(spec);
  u.component(0).fill(1.0f);
  Grid<float, 2> div(spec);
  proj.divergence(u, div);
  const double before = maxAbs(div);  // the free stream runs into the disc
  EXPECT_TRUE(proj.project(u, 0.01, 1.0).converged);
  proj.divergence(u, div);
  // PCG stops on its recursively updated residual; the true one, recomputed in float, may be a
  // little larger.
  EXPECT_LE(maxAbs(div), 2.0 * kTol * before);
  const auto& w = proj.faceWeights().component(0);
  double worst = 0.0;
  for (int i = 0; i <= 300; ++i) {
    double flux = 0.0;
    // Wall faces have weight 0 and carry the wall's velocity; fluid faces carry w u.
    const bool wall = i == 0 || i == 300;
    for (int j = 0; j < 100; ++j)
      flux += (wall ? 1.0 : w(IVec2(i, j))) * u.component(0)(IVec2(i, j)) * spec.dx;
    worst = std::max(worst, std::abs(flux - 1.0));
  }
  EXPECT_LT(worst, 1e-4);
  EXPECT_FLOAT_EQ(u.component(0)(IVec2(0, 50)), 1.0f);
  EXPECT_GT(u.component(0)(IVec2(50, 30)), 1.1f);  // beside the disc (x = 0.5, y = 0.3)
}
