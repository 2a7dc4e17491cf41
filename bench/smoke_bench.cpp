// One full 3D smoke step (Selle ch. 3.2: advect velocity, buoyancy + vorticity confinement,
// project, advect density and temperature) at 128 x 192 x 128 with a hot buoyant source, open
// top, MacCormack advection, MG-PCG projection. Counters give the seconds per step of each stage.
// BM_SmokeStepVortexParticles: Selle Fig. 3.4's explosion at half its resolution (90 x 130 x 90):
// a hot ball expanding at div u = 40 /s, without and with 750 vortex particles (radius 4 cells,
// vorticity tangent to circles about the vertical axis), the seed's claim being that they cost
// under 5% of a step.
#include <benchmark/benchmark.h>

#include <memory>
#include <utility>
#include <vector>

#include "msim/fluid/smoke/smoke_solver.hpp"

using namespace msim;

namespace {

constexpr double kStep = 1.0 / 48.0;

// The cells whose centres lie within `radius` of `centre`, fully covered: a ball source.
std::vector<std::pair<std::size_t, float>> ballCells(const fluid::SmokeSolver<3>& smoke, const Vec3& centre, double radius) {
  std::vector<std::pair<std::size_t, float>> cells;
  for (std::size_t i = 0; i < smoke.spec().cellCount(); ++i)
    if ((smoke.density().position(smoke.density().coord(i)) - centre).norm() < radius) cells.emplace_back(i, 1.0f);
  return cells;
}

// A plume from a hot vent near the floor, open top, after three steps (a developed plume, warm
// caches and pressure).
std::unique_ptr<fluid::SmokeSolver<3>> plume(const IVec3& res) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / res[0], res);
  fluid::SmokeParams<3> p;
  p.sides.side[1][1] = numerics::DomainSide::Open;
  p.buoyancy.alpha = 0.05;
  p.buoyancy.beta = 0.02;
  p.vorticityEpsilon = 0.3;
  p.projection.pcg.tolerance = 1e-4;
  auto smoke = std::make_unique<fluid::SmokeSolver<3>>(spec, p);
  fluid::SmokeSource<3> source;
  source.cells = ballCells(*smoke, Vec3(0.5, 0.1, 0.5), 0.08);
  source.density = 1.0;
  source.temperature = 400.0;
  source.velocity = Vec3(0.0, 0.5, 0.0);
  smoke->addSource(source);
  for (int k = 0; k < 3; ++k) smoke->step(kStep);
  smoke->resetTimers();
  return smoke;
}

// The explosion of scenes/explosion_vortex_particles.json at 90 x 130 x 90 (open but for the
// floor), after three steps of its expansion; with `particles`, that many vortex particles around
// the blast, as the scene seeds them.
std::unique_ptr<fluid::SmokeSolver<3>> explosion(int particles) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 90.0, IVec3(90, 130, 90));
  fluid::SmokeParams<3> p;
  for (int a = 0; a < 3; ++a)
    for (int side = 0; side < 2; ++side)
      if (a != 1 || side == 1) p.sides.side[a][side] = numerics::DomainSide::Open;
  p.buoyancy.alpha = 0.05;
  p.buoyancy.beta = 0.012;
  p.vorticityEpsilon = 0.0;
  auto smoke = std::make_unique<fluid::SmokeSolver<3>>(spec, p);
  fluid::SmokeSource<3> source;
  source.cells = ballCells(*smoke, Vec3(0.5, 0.2, 0.5), 0.08);
  source.density = 1.0;
  source.temperature = 700.0;
  source.expansion = 40.0;
  smoke->addSource(source);
  if (particles > 0) {
    fluid::VortexLayerSettings<3> v;
    v.seed.regionMin = Vec3(0.3, 0.08, 0.3);
    v.seed.regionMax = Vec3(0.7, 0.4, 0.7);
    v.seed.vorticity = fluid::SeedVorticity::Azimuthal;
    v.seed.radius = 4.0 * spec.dx;
    v.seed.strength = 8e-4;
    v.initialCount = static_cast<std::size_t>(particles);
    smoke->setVortexLayer(std::make_unique<fluid::VortexLayer<3>>(v, spec, "bench"));
  }
  for (int k = 0; k < 3; ++k) smoke->step(kStep / 4);
  smoke->resetTimers();
  return smoke;
}

void report(benchmark::State& state, const fluid::SmokeSolver<3>& smoke) {
  for (const auto& stage : smoke.timers().table())
    state.counters[stage.name] = stage.seconds / static_cast<double>(state.iterations());
  state.counters["pcg_it"] = smoke.statistics().pressureIterations;
  state.counters["cells"] = static_cast<double>(smoke.spec().cellCount());
}

void BM_SmokeStep3D(benchmark::State& state) {
  const IVec3 res(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)), static_cast<int>(state.range(0)));
  auto smoke = plume(res);
  for (auto _ : state) smoke->step(kStep);
  report(state, *smoke);
}

void BM_SmokeStepVortexParticles(benchmark::State& state) {
  auto smoke = explosion(static_cast<int>(state.range(0)));
  for (auto _ : state) smoke->step(kStep / 4);
  report(state, *smoke);
  state.counters["particles"] = static_cast<double>(smoke->statistics().vortexParticles);
}

}  // namespace

BENCHMARK(BM_SmokeStep3D)->Args({128, 192})->Args({64, 96})->Unit(benchmark::kMillisecond)->Iterations(3);
BENCHMARK(BM_SmokeStepVortexParticles)->Arg(0)->Arg(750)->Unit(benchmark::kMillisecond)->Iterations(8);
