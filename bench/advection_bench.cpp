// Time per step of semi-Lagrangian MacCormack advection (Selle ch. 2; RK2 trace, revert-to-first-
// order limiter) on a 128^3 grid: a cell-centred scalar (in one velocity, so the feet are reused,
// and in a new velocity every step), and all three components of a MAC grid;
// and the advection part of one 128x192x128 smoke step (three scalars and the velocity itself).
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr int kRes = 128;

const GridSpec<3>& spec() {
  static const GridSpec<3> s(Vec3::Zero(), 1.0 / kRes, IVec3::Constant(kRes));
  return s;
}

// A swirl about the z axis plus a uniform updraft, at CFL ~1.5.
MacGrid<3> swirl(const GridSpec<3>& spec = ::spec()) {
  MacGrid<3> v(spec);
  for (int a = 0; a < 3; ++a) {
    auto& g = v.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec3 p = g.position(g.coord(i)) - Vec3::Constant(0.5);
      g[i] = static_cast<float>(a == 0 ? -p.y() : (a == 1 ? p.x() : 0.3));
    }
  }
  return v;
}

void BM_MacCormackScalar128(benchmark::State& state) {
  const MacGrid<3> velocity = swirl();
  Grid<float, 3> phi(spec());
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = std::sin(10.0 * phi.position(phi.coord(i)).x());
  Advector<float, 3> advector(spec(), AdvectionSettings{});
  const double dt = 1.5 * spec().dx / 0.8;
  for (auto _ : state) advector.advect(phi, velocity, dt);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(phi.count()));
}
BENCHMARK(BM_MacCormackScalar128)->Unit(benchmark::kMillisecond)->UseRealTime();

// As above, but the velocity changes every step, so every step traces its feet afresh.
void BM_MacCormackScalar128NewVelocity(benchmark::State& state) {
  const MacGrid<3> first = swirl();
  MacGrid<3> second = first;
  for (int a = 0; a < 3; ++a)
    for (float& v : second.component(a).data()) v *= 0.9f;
  Grid<float, 3> phi(spec());
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = std::sin(10.0 * phi.position(phi.coord(i)).x());
  Advector<float, 3> advector(spec(), AdvectionSettings{});
  const double dt = 1.5 * spec().dx / 0.8;
  int n = 0;
  for (auto _ : state) advector.advect(phi, n++ % 2 ? second : first, dt);
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(phi.count()));
}
BENCHMARK(BM_MacCormackScalar128NewVelocity)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_MacCormackMacGrid128(benchmark::State& state) {
  const MacGrid<3> velocity = swirl();
  MacGrid<3> field = velocity;
  Advector<float, 3> advector(spec(), AdvectionSettings{});
  const double dt = 1.5 * spec().dx / 0.8;
  advector.advect(field, velocity, dt);  // first use allocates the scratch memory
  for (auto _ : state) advector.advect(field, velocity, dt);
  state.SetItemsProcessed(state.iterations() * 3 * static_cast<int64_t>(spec().cellCount()));
}
BENCHMARK(BM_MacCormackMacGrid128)->Unit(benchmark::kMillisecond)->UseRealTime();

// Density, temperature and a third scalar moved by u^n (the feet are traced once and reused),
// then u^n itself (each face component traces its own feet).
void BM_SmokeStepAdvection128x192x128(benchmark::State& state) {
  const GridSpec<3> smoke(Vec3::Zero(), 1.0 / kRes, IVec3(128, 192, 128));
  const MacGrid<3> start = swirl(smoke);
  std::vector<Grid<float, 3>> scalars(3, Grid<float, 3>(smoke));
  for (std::size_t s = 0; s < scalars.size(); ++s)
    for (std::size_t i = 0; i < scalars[s].count(); ++i)
      scalars[s][i] = std::sin((10.0 + s) * scalars[s].position(scalars[s].coord(i)).x());
  Advector<float, 3> advector(smoke, AdvectionSettings{});
  const double dt = 1.5 * smoke.dx / 0.8;
  MacGrid<3> velocity = start;
  for (auto& phi : scalars) advector.advect(phi, velocity, dt);  // first use allocates the scratch memory
  advector.advect(velocity, velocity, dt);
  for (auto _ : state) {
    state.PauseTiming();
    velocity = start;
    state.ResumeTiming();
    for (auto& phi : scalars) advector.advect(phi, velocity, dt);
    advector.advect(velocity, velocity, dt);
  }
  state.SetItemsProcessed(state.iterations() * static_cast<int64_t>(smoke.cellCount()));
}
BENCHMARK(BM_SmokeStepAdvection128x192x128)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
