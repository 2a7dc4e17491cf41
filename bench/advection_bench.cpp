// Time per step of semi-Lagrangian MacCormack advection (Selle ch. 2; RK2 trace, revert-to-first-
// order limiter) on a 128^3 grid: a cell-centred scalar, and all three components of a MAC grid.
#include <benchmark/benchmark.h>

#include <cmath>

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
MacGrid<3> swirl() {
  MacGrid<3> v(spec());
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

void BM_MacCormackMacGrid128(benchmark::State& state) {
  const MacGrid<3> velocity = swirl();
  MacGrid<3> field = velocity;
  Advector<float, 3> advector(spec(), AdvectionSettings{});
  const double dt = 1.5 * spec().dx / 0.8;
  for (auto _ : state) advector.advect(field, velocity, dt);
  state.SetItemsProcessed(state.iterations() * 3 * static_cast<int64_t>(spec().cellCount()));
}
BENCHMARK(BM_MacCormackMacGrid128)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
