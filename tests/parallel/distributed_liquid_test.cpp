// A 3D dam break tracked by the particle level set (Selle ch. 4.4.3), split among the ranks
// (Selle ch. 8.1): phi and the velocity exchanged before every stencil, the marker particles
// migrated to the rank whose cells hold them and their copies near a block read by the
// correction, the fast marching on each block with ceil(band) ghost layers, the pressure through
// hypre. Against the same run on one rank and the serial solver.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <optional>
#include <tuple>

#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "msim/parallel/mpi_domain_split.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/parallel/particle_migration.hpp"
#include "mpi_test_support.hpp"

namespace msim::parallel {
namespace {

using testing::fromRoot;
using testing::sendToRoot;
using testing::referenceRuns;
using testing::References;
using testing::worldRank;
using testing::worldSize;

const GridSpec<3> kLiquidGrid(Vec<3>::Zero(), 1.0 / 32, IVec<3>(32, 28, 24));
constexpr int kLiquidSteps = 40;
constexpr double kLiquidDt = 0.004;  // [s]; the water reaches about 1.5 m/s: 0.2 cells per step

struct LiquidRun {
  Grid<float, 3> phi;     // on rank 0 (split runs: gathered)
  double volume = 0.0;    // [m^3]
  double targetVolume = 0.0;  // volume control's: the start's plus what came in less what went
  double initialVolume = 0.0;
  std::size_t particles = 0;
  long particlesLost = 0;   // over the steps without reseeding: count before less count after
  long strayParticles = 0;  // particles held by a rank that does not own their cell
  std::size_t vortexParticles = 0;
};

// What a run holds besides the water: a rock it runs against (cut by the blocks' edges), vortex
// particles spinning the column (every rank keeps them all; those reaching the air are deleted),
// or an emitter against the z_min wall, across the blocks' cut, letting water in through it and a
// sink on the floor taking it out; or the water carried by FLIP particles instead.
enum class Extra { None, Rock, VortexParticles, EmitterAndSink, Flip };

// A column of water against the x_min wall, collapsing, and a ball of water falling beside it.
Grid<float, 3> water(const GridSpec<3>& spec) {
  Grid<float, 3> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec<3> x = phi.position(phi.coord(i));
    const double column = std::max(x[0] - 0.35, x[1] - 0.55);
    const double ball = (x - Vec<3>(0.72, 0.5, 0.4)).norm() - 0.13;
    phi[i] = static_cast<float>(std::min(column, ball));
  }
  return phi;
}

LiquidRun runDamBreak(const GridSpec<3>& spec, DomainSplit<3>* split, Extra extra) {
  fluid::LiquidParams<3> params;
  if (extra == Extra::Flip) params.tracker = fluid::InterfaceTracker::Flip;
  fluid::LiquidSolver<3> solver(spec, params);
  solver.setDomainSplit(split);
  if (extra == Extra::Rock)
    solver.setObstacles(numerics::sampleNodes<3>(spec, [](const Vec<3>& x) { return (x - Vec<3>(0.5, 0.1, 0.37)).norm() - 0.16; }));
  solver.addLiquid(water(spec));
  if (extra == Extra::VortexParticles) {
    fluid::VortexLayerSettings<3> v;
    v.seed.regionMin = Vec<3>(0.02, 0.05, 0.05);
    v.seed.regionMax = Vec<3>(0.33, 0.7, 0.7);  // above the column's top (0.55): deleted in the air
    v.seed.magnitude = 30.0;
    v.seed.radius = 3.0 * kLiquidGrid.dx;
    v.seed.strength = 2e-4;
    v.initialCount = 300;
    solver.setVortexLayer(std::make_unique<fluid::VortexLayer<3>>(v, kLiquidGrid, "test vortex particles"));
  }
  const auto box = [&](const Vec<3>& lo, const Vec<3>& hi) {
    Grid<float, 3> region(spec);
    for (std::size_t i = 0; i < region.count(); ++i) {
      const Vec<3> x = region.position(region.coord(i));
      region[i] = static_cast<float>(std::max((lo - x).maxCoeff(), (x - hi).maxCoeff()));
    }
    return region;
  };
  const Grid<float, 3> emitter = box(Vec<3>(0.4, 0.2, 0.0), Vec<3>(0.62, 0.32, 0.08));
  const Grid<float, 3> sink = box(Vec<3>(0.8, 0.0, 0.3), Vec<3>(1.0, 0.08, 0.5));
  LiquidRun run;
  run.initialVolume = solver.liquidVolume();
  for (int s = 0; s < kLiquidSteps; ++s) {
    EXPECT_LE(kLiquidDt, solver.cflTimestep()) << "step " << s;
    const std::size_t before = solver.statistics().particles;
    if (extra == Extra::EmitterAndSink) {
      solver.emit(emitter, Vec<3>(0.0, 0.0, 1.2));
      solver.drain(sink);
    }
    solver.step(kLiquidDt);
    const bool reseeded = extra != Extra::Flip && solver.steps() % solver.params().reseedInterval == 0;
    if (s > 0 && !reseeded && extra != Extra::EmitterAndSink)  // they delete the particles in their shapes
      run.particlesLost += long(before) - long(solver.statistics().particles);
  }
  const fluid::LiquidStatistics stats = solver.statistics();
  run.volume = stats.volume;
  run.targetVolume = stats.targetVolume;
  run.particles = stats.particles;
  run.vortexParticles = stats.vortexParticles;
  if (split) {
    const auto& mpi = static_cast<const MpiDomainSplit&>(*split);
    for (const Vec<3>& x : solver.levelSetParticles().positions())
      run.strayParticles += ownerOf<3>(x, mpi.block()) != mpi.block().rank;
    for (const Vecf<3>& x : solver.flipParticles().positions())
      run.strayParticles += ownerOf<3>(x, mpi.block()) != mpi.block().rank;
    long stray = run.strayParticles;
    MPI_Allreduce(MPI_IN_PLACE, &stray, 1, MPI_LONG, MPI_SUM, mpi.comm());
    run.strayParticles = stray;
    run.phi = gatherToRoot(solver.phi(), mpi.block(), mpi.comm());
  } else {
    run.phi = solver.phi();
  }
  return run;
}

// `extraLayers` beyond what liquidGhostLayers asks for (ceil(band) = 6).
LiquidRun runSplit(MPI_Comm comm, Extra extra, int extraLayers = 0) {
  const fluid::LiquidParams<3> params;
  const int ghost = liquidGhostLayers(params.advection, params.cfl, params.bandCells) + extraLayers;
  const GridBlock<3> block(kLiquidGrid, BlockDecomposition<3>(kLiquidGrid.res, sizeOf(comm), ghost, "test"), rankOf(comm),
                           ghost);
  MpiDomainSplit split(block, params.sides, params.projection.pcg, comm);
  return runDamBreak(block.localSpec(), &split, extra);
}

// Largest |a - b| [cells] over the cells within 3 cells of b's surface.
double surfaceDifference(const Grid<float, 3>& a, const Grid<float, 3>& b) {
  double worst = 0.0;
  for (std::size_t i = 0; i < a.count(); ++i)
    if (std::abs(b[i]) < 3.0 * kLiquidGrid.dx) worst = std::max(worst, double(std::abs(a[i] - b[i])));
  return worst / kLiquidGrid.dx;
}

// The split run against the one-rank run and the serial solver (MG-PCG). With ceil(band) ghost
// layers the fast marching of a block differs from the whole grid's where a cell's upwind cone
// leaves the ghosts (tests/parallel/split_level_set_test.cpp), and the surface carries that from
// step to step: 0.068 cells after 40 steps on 2, 4 and 8 ranks (0.134 with the rock, whose
// solid extension of phi feeds the march); four layers more bring it to 5e-4 (1e-3).
// With the emitter (in through the wall) and the sink, volume control's target, which follows what
// they add and take, equals the one-rank run's.
// Every particle lies in its owner's cells, and no step without reseeding changes their count.
class DistributedLiquid : public ::testing::TestWithParam<std::tuple<Extra, int>> {};

TEST_P(DistributedLiquid, DamBreakFollowsTheOneRankRun) {
  const auto [extra, extraLayers] = GetParam();
  // The rock on 8 ranks (blocks touching at corners), the others on 2.
  if (worldSize() != (extra == Extra::Rock ? 8 : 2)) GTEST_SKIP() << "run on 2 ranks (the rock on 8)";
  const References<LiquidRun> ref = referenceRuns(
      [&](MPI_Comm alone) { return runSplit(alone, extra); }, [&] { return runDamBreak(kLiquidGrid, nullptr, extra); },
      LiquidRun{Grid<float, 3>(kLiquidGrid)}, [](LiquidRun& run, int from) {
        sendToRoot(run.phi.data(), from);
        std::vector<double> numbers = {run.volume, run.targetVolume, double(run.vortexParticles)};
        sendToRoot(numbers, from);
        run.volume = numbers[0];
        run.targetVolume = numbers[1];
        run.vortexParticles = static_cast<std::size_t>(numbers[2]);
      });
  const auto& one = ref.one;
  const auto& serial = ref.serial;
  const LiquidRun split = runSplit(MPI_COMM_WORLD, extra, extraLayers);
  EXPECT_EQ(split.strayParticles, 0);
  EXPECT_EQ(split.particlesLost, 0);
  if (worldRank() == 0) {
    const double toOne = surfaceDifference(split.phi, one->phi), toSerial = surfaceDifference(split.phi, serial->phi);
    const double volumeToOne = split.volume / one->volume - 1.0, volumeToSerial = split.volume / serial->volume - 1.0;
    const double particlesToOne = double(split.particles) / double(one->particles) - 1.0;
    std::printf("liquid dam break%s, %d steps on %d ranks with %d more ghost layers: surface within %.3g cells of the "
                "one-rank run's (serial solver: %.3g), volume %+.2e (%+.2e), particles %zu vs %zu (%+.2e)\n",
                extra == Extra::Rock              ? " against a rock"
                : extra == Extra::VortexParticles ? " with vortex particles"
                : extra == Extra::EmitterAndSink  ? " with an emitter and a sink"
                : extra == Extra::Flip            ? ", FLIP"
                                                  : "",
                kLiquidSteps, worldSize(), extraLayers, toOne, toSerial, volumeToOne, volumeToSerial, split.particles,
                one->particles, particlesToOne);
    // FLIP rebuilds its surface from the particles every step, switching cells between deep inside
    // and the kernel's value: the fast marching's differences grow (the particles, bit for bit for 30
    // steps, part at the 1e-7 level by 35 and then 0.002 cells at 10 layers, 0.54 at 6).
    const bool flip = extra == Extra::Flip;
    const double surfaceLimit = extraLayers == 0 ? 0.2 : flip ? 0.004 : 0.002;
    EXPECT_LT(toOne, surfaceLimit);
    // hypre and MG-PCG: 3e-4 cells apart on one rank; the vortex particles spin that up to 0.009.
    EXPECT_LT(toSerial, extra == Extra::VortexParticles ? 0.02 : surfaceLimit + 0.001);
    EXPECT_LT(std::abs(volumeToOne), flip ? 1e-4 : 1e-5);
    EXPECT_LT(std::abs(volumeToSerial), flip ? 1e-4 : 1e-5);
    EXPECT_LT(std::abs(particlesToOne), 1e-3);
    if (extra == Extra::EmitterAndSink) {
      std::printf("target volume %.6g m^3 (one rank %.6g, serial %.6g)\n", split.targetVolume, one->targetVolume,
                  serial->targetVolume);
      EXPECT_LT(std::abs(split.targetVolume / one->targetVolume - 1.0), 1e-5);
      EXPECT_GT(split.targetVolume, 1.02 * split.initialVolume);  // the emitter let water in
    }
    if (extra == Extra::VortexParticles) {
      std::printf("vortex particles: %zu (one rank %zu, serial %zu)\n", split.vortexParticles, one->vortexParticles,
                  serial->vortexParticles);
      EXPECT_GT(split.vortexParticles, 100u);
      EXPECT_LT(split.vortexParticles, 290u);  // some were in the air
      EXPECT_EQ(split.vortexParticles, one->vortexParticles);
    }
  }
  EXPECT_TRUE(fromRoot(!::testing::Test::HasFailure()));
}

// The rock with wider ghost layers measured 0.001 cells (docs/parallel.md), not run here; the
// vortex particles and the emitter with wider ones, so that their own effect shows (the emitter's
// box corners, across the cut, feed the fast marching: 0.0056 cells at 10 layers, 1e-5 at 14).
INSTANTIATE_TEST_SUITE_P(ExtrasAndGhostLayers, DistributedLiquid,
                         ::testing::Values(std::make_tuple(Extra::None, 0), std::make_tuple(Extra::None, 4),
                                           std::make_tuple(Extra::Rock, 0), std::make_tuple(Extra::VortexParticles, 4),
                                           std::make_tuple(Extra::EmitterAndSink, 8), std::make_tuple(Extra::Flip, 4)));

}  // namespace
}  // namespace msim::parallel
