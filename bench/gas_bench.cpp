// Cost of one gas step (two scalars advected and diffused: 2 x 2 RK stages of flux evaluation)
// at the steam scene's grid and at 128^3, and the finite-volume transport alone.
#include <benchmark/benchmark.h>

#include "msim/fluid/gas/gas_solver.hpp"

using namespace msim;

namespace {

fluid::MotionField steamLikeField() {
  fluid::MotionFieldInstance up;
  up.type = fluid::MotionPrimitive::Directional;
  up.axis = Vec3::UnitY();
  up.position = Vec3(0.5, 0.05, 0.5);
  up.scale = Vec3(0.15, 0.15, 0.3);
  up.magnitude = 0.5;
  up.halfDistance = 3.0;
  fluid::MotionFieldInstance swirl;
  swirl.type = fluid::MotionPrimitive::LineVortex;
  swirl.position = Vec3(0.4, 0.5, 0.5);
  swirl.magnitude = 0.05;
  swirl.coreRadius = 0.08;
  return fluid::MotionField({up, swirl});
}

void BM_GasStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const IVec3 res(n, static_cast<int>(state.range(1)), n);
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / res.maxCoeff(), res);
  fluid::GasSolver<3> gas(spec, fluid::GasParams{.densityDiffusion = 1e-5, .temperatureDiffusion = 1e-5},
                          steamLikeField(), numerics::TransportBoundaries<3>::allOpen());
  gas.density().fill(0.5f);
  const double dt = gas.stableTimestep();
  for (auto _ : state) gas.step(dt);
  state.counters["cells"] = static_cast<double>(spec.cellCount());
  state.counters["time/cell"] = benchmark::Counter(static_cast<double>(spec.cellCount()),
                                                 benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}

}  // namespace

BENCHMARK(BM_GasStep)->Args({64, 128})->Args({128, 128})->Unit(benchmark::kMillisecond)->UseRealTime();
