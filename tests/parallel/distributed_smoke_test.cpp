// A 3D smoke plume (sources with inflow, buoyancy, vorticity confinement, MacCormack, open top),
// alone, split by a ball at rest, swept by a moving ball, in a wind tunnel, from an expanding
// source, viscous, with the scalars moved in flux form and with vortex particles, run for 50 steps
// split among the ranks gives the density of the same run on one rank within 1e-4 relative (the
// issue's check), and stays close to the serial solver with its own MG-PCG.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>

#include "msim/fluid/smoke/smoke_solver.hpp"
#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "msim/parallel/mpi_domain_split.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::fromRoot;
using testing::sendToRoot;
using testing::referenceRuns;
using testing::References;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kSmokeGrid(Vec<3>::Zero(), 1.0 / 40, IVec<3>(40, 48, 36));
constexpr int kSmokeSteps = 50;
constexpr double kSmokeDt = 0.008;

fluid::SmokeParams<3> plumeParams() {
  fluid::SmokeParams<3> p;
  p.sides.side[1][1] = numerics::DomainSide::Open;
  p.buoyancy.alpha = 0.02;
  p.buoyancy.beta = 0.04;
  p.buoyancy.ambientTemperature = 300.0;
  p.vorticityEpsilon = 0.2;
  p.projection.pcg.tolerance = 1e-6;
  p.densityDissipation = 0.05;
  return p;
}

// A ball of hot smoke blowing upwards near the floor, voxelised on `spec` (the whole grid or a block).
fluid::SmokeSource<3> plumeSource(const GridSpec<3>& spec, double expansion = 0.0) {
  fluid::SmokeSource<3> src;
  src.expansion = expansion;
  src.density = 1.0;
  src.temperature = 420.0;
  src.velocity = Vec<3>(0.2, 1.2, 0.0);
  const Vec<3> centre(0.45, 0.15, 0.42);
  const double radius = 0.12;
  Grid<float, 3> cells(spec);
  for (std::size_t i = 0; i < cells.count(); ++i) {
    const double d = (cells.position(cells.coord(i)) - centre).norm() - radius;
    const double coverage = std::clamp(0.5 - d / spec.dx, 0.0, 1.0);
    if (coverage > 0.0) src.cells.emplace_back(i, static_cast<float>(coverage));
  }
  return src;
}

// The plume alone, split by a ball at rest, or by a ball that swings across it once in the 50
// steps (a moving obstacle: its faces push the smoke through the pressure solve); the plume and
// the ball in a wind tunnel; the plume from a source whose gas expands (a target divergence); the
// plume around the ball with viscosity, with the conservative (flux-form MUSCL) scalar transport, and
// with vortex particles seeded in the vent that spin the air and are pushed out of the ball, seeded
// with random vorticity or with the flow's own.
enum class Variant { Plume, Ball, MovingBall, Tunnel, Expanding, Viscous, Conservative, Vortex, VortexLocalFlow };
const Vec<3> kSwing(0.1, 0.0, 0.04);                   // amplitude [m]
const double kOmega = 2.0 * 3.14159265358979 / 0.4;   // [1/s]

// The ball at time t (negative inside), and its velocity.
double ballDistance(const Vec<3>& x, Variant variant, double t) {
  const Vec<3> centre = Vec<3>(0.5, 0.55, 0.45) + (variant == Variant::MovingBall ? std::sin(kOmega * t) : 0.0) * kSwing;
  return (x - centre).norm() - 0.13;
}
Vec<3> ballVelocity(double t) { return kOmega * std::cos(kOmega * t) * kSwing; }

// The tunnel variant: the plume in a wind, blown in through the x_min wall (moving along its
// normal) and out through an open x_max side, around the ball at rest.
fluid::SmokeParams<3> variantParams(Variant variant) {
  fluid::SmokeParams<3> p = plumeParams();
  if (variant == Variant::Conservative) p.scalarTransport = fluid::ScalarTransport::Conservative;
  // The expanding source's target dominates the right-hand side's max-norm, against which the
  // solvers' tolerance is taken, so 1e-6 leaves the rest of the field loose: hypre's PFMG on 8
  // blocks and on 1 stop 2.7e-4 apart in density after 50 steps (1, 2 and 4 bit for bit).
  if (variant == Variant::Expanding) p.projection.pcg.tolerance = 1e-8;
  if (variant == Variant::Viscous) p.viscosity = 0.05;  // implicit (nu dt / dx^2 = 0.64): a CG over the blocks
  if (variant == Variant::Tunnel) {
    p.wallVelocity[0][0] = Vec<3>(0.5, 0.0, 0.0);
    p.sides.side[0][1] = numerics::DomainSide::Open;
  }
  return p;
}

Grid<float, 3> runPlume(const GridSpec<3>& spec, DomainSplit<3>* split, Variant variant) {
  fluid::SmokeSolver<3> solver(spec, variantParams(variant));
  solver.setDomainSplit(split);  // first, as the smoke phenomenon does: the vortex particles seed on the split
  const auto place = [&](double t) {
    solver.setObstacles(numerics::sampleNodes<3>(spec, [&](const Vec<3>& x) { return ballDistance(x, variant, t); }));
    if (variant == Variant::MovingBall) {
      MacGrid<3> velocity(spec);
      for (int a = 0; a < 3; ++a) velocity.component(a).fill(static_cast<float>(ballVelocity(t)[a]));
      solver.setObstacleVelocity(velocity);
    }
  };
  if (variant == Variant::Vortex || variant == Variant::VortexLocalFlow) {
    // Every rank seeds the same particles over the global domain (the same random stream); set
    // before the obstacle, which the layer then takes.
    fluid::VortexLayerSettings<3> v;
    v.seed.regionMin = Vec<3>(0.35, 0.05, 0.32);
    v.seed.regionMax = Vec<3>(0.55, 0.25, 0.52);
    v.seed.magnitude = 40.0;
    v.seed.radius = 3.0 * kSmokeGrid.dx;
    v.seed.strength = 1e-4;
    v.initialCount = 100;
    v.rate = 2000.0;
    v.solids = fluid::VortexSolidHandling::PushOut;
    if (variant == Variant::VortexLocalFlow) {  // the flow's vorticity where it exceeds 5 /s, read by the owners
      v.seed.vorticity = fluid::SeedVorticity::LocalFlow;
      v.seed.minimumFlowVorticity = 5.0;
    }
    solver.setVortexLayer(std::make_unique<fluid::VortexLayer<3>>(v, kSmokeGrid, "test vortex particles"));
  }
  if (variant != Variant::Plume && variant != Variant::Expanding) place(0.0);
  solver.addSource(plumeSource(spec, variant == Variant::Expanding ? 4.0 : 0.0));
  for (int s = 0; s < kSmokeSteps; ++s) {
    EXPECT_LE(kSmokeDt, solver.cflTimestep()) << "step " << s;
    if (variant == Variant::MovingBall) place((s + 0.5) * kSmokeDt);
    solver.step(kSmokeDt);
  }
  return solver.density();
}

Grid<float, 3> runSplit(MPI_Comm comm, Variant variant) {
  const fluid::SmokeParams<3> params = variantParams(variant);
  const GridBlock<3> block(kSmokeGrid, BlockDecomposition<3>(kSmokeGrid.res, sizeOf(comm), 4, "test"), rankOf(comm),
                           smokeGhostLayers(params.advection, 1.0,
                                            params.scalarTransport == fluid::ScalarTransport::Conservative));
  MpiDomainSplit split(block, params.sides, params.projection.pcg, comm);
  return gatherToRoot(runPlume(block.localSpec(), &split, variant), block, comm);
}

double maxAbs(const Grid<float, 3>& g) {
  double m = 0.0;
  for (float v : g.data()) m = std::max(m, double(std::abs(v)));
  return m;
}

double maxDifference(const Grid<float, 3>& a, const Grid<float, 3>& b) {
  double m = 0.0;
  for (std::size_t i = 0; i < a.count(); ++i) m = std::max(m, double(std::abs(a[i] - b[i])));
  return m;
}

class DistributedSmoke : public ::testing::TestWithParam<Variant> {};

TEST_P(DistributedSmoke, FiftyStepsMatchOneRankWithin1e4Relative) {
  const Variant variant = GetParam();
  // The plume, alone and around the ball, on every rank count; the other variants on 2 (one cut)
  // and 8 (blocks touching at corners) ranks, which hold every kind of block edge.
  if (variant != Variant::Plume && variant != Variant::Ball && worldSize() != 2 && worldSize() != 8)
    GTEST_SKIP() << "run on 2 and 8 ranks";
  // The flow-vorticity seeding reads at the owners as the vortex variant does (run on 8 ranks).
  if (variant == Variant::VortexLocalFlow && worldSize() != 2) GTEST_SKIP() << "run on 2 ranks";
  // The implicit viscosity's CG reads a 7-point stencil: face neighbours only, which one cut holds
  // (on 8 oversubscribed ranks its hundreds of exchanges took a fifth of the MPI tests' time).
  if (variant == Variant::Viscous && worldSize() != 2) GTEST_SKIP() << "run on 2 ranks";
  // The one-rank run and the serial solver's, then the split run on every rank.
  const References<Grid<float, 3>> ref = referenceRuns(
      [&](MPI_Comm alone) { return runSplit(alone, variant); }, [&] { return runPlume(kSmokeGrid, nullptr, variant); },
      Grid<float, 3>(kSmokeGrid), [](Grid<float, 3>& g, int from) { sendToRoot(g.data(), from); });
  const auto& one = ref.one;
  const auto& serial = ref.serial;
  const Grid<float, 3> split = runSplit(MPI_COMM_WORLD, variant);
  bool ok = true;
  if (worldRank() == 0) {
    const double scale = maxAbs(*one);
    const double toOne = maxDifference(split, *one) / scale, toSerial = maxDifference(split, *serial) / scale;
    const char* name = variant == Variant::Plume        ? ""
                       : variant == Variant::Ball       ? " around a ball"
                       : variant == Variant::MovingBall ? " swept by a moving ball"
                       : variant == Variant::Tunnel     ? " in a wind tunnel around a ball"
                       : variant == Variant::Expanding  ? " from an expanding source"
                       : variant == Variant::Viscous    ? " around a ball, viscous"
                       : variant == Variant::Vortex     ? " around a ball, with vortex particles"
                       : variant == Variant::VortexLocalFlow ? " around a ball, with vortex particles of the flow's vorticity"
                                                        : " around a ball, scalars in flux form";
    std::printf("smoke plume%s, %d steps on %d ranks: max density %.3f; relative difference to 1 rank %.1e, to the "
                "serial MG-PCG solver %.1e\n", name, kSmokeSteps, worldSize(), scale, toOne, toSerial);
    EXPECT_GT(scale, 0.5);
    EXPECT_LT(toOne, 1e-4);
    EXPECT_LT(toSerial, 1e-2);
    ok = !::testing::Test::HasFailure();
  }
  EXPECT_TRUE(fromRoot(ok));
}

INSTANTIATE_TEST_SUITE_P(Variants, DistributedSmoke,
                         ::testing::Values(Variant::Plume, Variant::Ball, Variant::MovingBall, Variant::Tunnel,
                                           Variant::Expanding, Variant::Viscous, Variant::Conservative, Variant::Vortex,
                                           Variant::VortexLocalFlow));

}  // namespace
}  // namespace msim::parallel
