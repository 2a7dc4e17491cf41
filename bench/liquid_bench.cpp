// One 3D dam-break step of the liquid solver (surface tracking, velocity self-advection or
// particle transfers, gravity, ghost-fluid pressure with MIC(0)-PCG, velocity extension) with the
// liquid filling a quarter of the box, 0.2 s into the collapse. Arguments: cells along x (y is
// 1.5x, z = x), tracker (0: particle level set, 1: FLIP). Counters: seconds per step of each
// stage, PCG iterations, particles, liquid cells.
#include <benchmark/benchmark.h>

#include <algorithm>

#include "msim/core/timer.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/fluid/liquid/liquid_turbulence.hpp"

using namespace msim;

namespace {

void BM_LiquidDamBreakStep3D(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const IVec3 res(n, n * 3 / 2, n);
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, res);
  fluid::LiquidParams<3> params;
  params.tracker = state.range(1) == 0 ? fluid::InterfaceTracker::ParticleLevelSet : fluid::InterfaceTracker::Flip;
  params.projection.pcg.tolerance = 1e-4;
  fluid::LiquidSolver<3> liquid(spec, params);
  Grid<float, 3> column(spec);
  for (std::size_t i = 0; i < column.count(); ++i) {
    const Vec3 x = column.position(column.coord(i));
    column[i] = static_cast<float>(std::max(x[0] - 0.5, x[1] - 0.75));  // a quarter of the box
  }
  liquid.addLiquid(column);
  for (int k = 0; k < 4; ++k) liquid.advance(0.05);  // 0.2 s into the collapse
  liquid.resetTimers();
  long steps = 0;
  for (auto _ : state) {
    liquid.step(std::min(1.0 / 60.0, liquid.cflTimestep()));
    ++steps;
  }
  for (const auto& stage : liquid.timers().table())
    state.counters[stage.name] = stage.seconds / static_cast<double>(steps);
  const fluid::LiquidStatistics s = liquid.statistics();
  state.counters["pcg_it"] = s.pressureIterations;
  state.counters["particles"] = static_cast<double>(s.particles);
  state.counters["cells"] = static_cast<double>(spec.cellCount());
}

}  // namespace

BENCHMARK(BM_LiquidDamBreakStep3D)
    ->Args({64, 0})
    ->Args({64, 1})
    ->Args({128, 0})
    ->Args({128, 1})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(3);

namespace {

// One step of the liquid's sub-grid turbulence (Narain ch. 3.5.3, refinement 4) on the same dam
// break at the simulation grid n x 1.5n x n, 0.2 s in: energy, noise particles and u' in the band
// round the surface, the fine surface advected twice and relaxed. Counters: seconds per stage of
// the turbulence and of the liquid's own step, fine cells, the band's share of the fine nodes.
void BM_LiquidTurbulenceStep3D(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3(n, n * 3 / 2, n));
  fluid::LiquidParams<3> params;
  params.projection.pcg.tolerance = 1e-4;
  fluid::LiquidSolver<3> liquid(spec, params);
  Grid<float, 3> column(spec);
  for (std::size_t i = 0; i < column.count(); ++i) {
    const Vec3 x = column.position(column.coord(i));
    column[i] = static_cast<float>(std::max(x[0] - 0.5, x[1] - 0.75));
  }
  liquid.addLiquid(column);
  fluid::LiquidTurbulenceParams turbulenceParams;
  fluid::LiquidTurbulence<3> turbulence(spec, turbulenceParams, params.advection, liquid.phi(), nullptr);
  for (int k = 0; k < 12; ++k) {
    const double dt = std::min(1.0 / 60.0, liquid.cflTimestep());
    liquid.step(dt);
    turbulence.step(liquid.velocity(), liquid.phi(), dt);
  }
  liquid.resetTimers();
  turbulence.resetTimers();
  long steps = 0;
  for (auto _ : state) {
    const double dt = std::min(1.0 / 60.0, liquid.cflTimestep());
    liquid.step(dt);
    turbulence.step(liquid.velocity(), liquid.phi(), dt);
    ++steps;
  }
  double liquidSeconds = 0.0;
  for (const auto& stage : liquid.timers().table()) liquidSeconds += stage.seconds;
  state.counters["liquid"] = liquidSeconds / static_cast<double>(steps);
  for (const auto& stage : turbulence.timers().table())
    state.counters["turb_" + stage.name] = stage.seconds / static_cast<double>(steps);
  state.counters["fine_cells"] = static_cast<double>(turbulence.fineSpec().cellCount());
  state.counters["band"] = turbulence.bandFraction();
}

}  // namespace

BENCHMARK(BM_LiquidTurbulenceStep3D)->Arg(32)->Arg(48)->Unit(benchmark::kMillisecond)->Iterations(3);
