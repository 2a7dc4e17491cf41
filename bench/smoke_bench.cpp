// One full 3D smoke step (Selle ch. 3.2: advect velocity, buoyancy + vorticity confinement,
// project, advect density and temperature) at 128 x 192 x 128 with a hot buoyant source, open
// top, MacCormack advection, MG-PCG projection. Counters give the seconds per step of each stage.
#include <benchmark/benchmark.h>

#include "msim/fluid/smoke/smoke_solver.hpp"

using namespace msim;

namespace {

void BM_SmokeStep3D(benchmark::State& state) {
  const IVec3 res(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), static_cast<int>(state.range(0)));
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / res[0], res);
  fluid::SmokeParams<3> p;
  p.sides.side[1][1] = numerics::DomainSide::Open;
  p.buoyancy.alpha = 0.05;
  p.buoyancy.beta = 0.02;
  p.vorticityEpsilon = 0.3;
  p.projection.pcg.tolerance = 1e-4;
  fluid::SmokeSolver<3> smoke(spec, p);
  fluid::SmokeSource<3> source;
  const Vec3 centre(0.5, 0.1, 0.5);
  for (std::size_t i = 0; i < spec.cellCount(); ++i)
    if ((smoke.density().position(smoke.density().coord(i)) - centre).norm() < 0.08) source.cells.emplace_back(i, 1.0f);
  source.density = 1.0;
  source.temperature = 400.0;
  source.velocity = Vec3(0.0, 0.5, 0.0);
  smoke.addSource(source);
  const double dt = 1.0 / 48.0;
  for (int k = 0; k < 3; ++k) smoke.step(dt);  // a developed plume, warm caches and pressure
  smoke.resetTimers();
  for (auto _ : state) smoke.step(dt);
  for (const auto& stage : smoke.timers().table())
    state.counters[stage.name] = stage.seconds / static_cast<double>(state.iterations());
  state.counters["pcg_it"] = smoke.statistics().pressureIterations;
  state.counters["cells"] = static_cast<double>(spec.cellCount());
}

}  // namespace

BENCHMARK(BM_SmokeStep3D)->Args({128, 192})->Args({64, 96})->Unit(benchmark::kMillisecond)->Iterations(3);
