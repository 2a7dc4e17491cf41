// UIC projection (Narain 2011, ch. 4.4) on converging crowds: a square lattice at 0.9 rho_max
// whose agents all walk at 1.4 m/s towards its centre, dt = 0.1 s, dx = 1.5 m, rho_max = 4 / m^2.
// Each benchmark iteration is one projection followed by x += v dt (so the pressure warm starts
// from the previous step, as in a run); every 40 steps the crowd is reset to the lattice.
//   BM_UicCrowd/40/10000, /400/1000000   the table 4.1 sizes of the brief: 10k agents on 40x40,
//                                          1M agents on 400x400 (whole projection, eq. 4.1-4.3)
//   BM_UicActiveCells/<half width>        cost vs number of constrained cells: 128x128 grid, the
//                                          lattice a square of the given half width [cells]
//   BM_UicAgentsPerCell/<10 dx>           cost vs agent count at fixed cells: 128x128, half width
//                                          16 cells, dx 1.5 / 3 / 6 m (0.9 rho_max dx^2 agents a cell)
// Counters: agents, active cells (p > 0), QP iterations (inner + outer), and the split of the
// time into splat / solve / agents, all averaged over the iterations.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "msim/crowd/uic_projection.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

constexpr double kDx = 1.5, kRhoMax = 4.0, kDt = 0.1;
constexpr int kCycle = 40;  // steps between resets to the lattice

struct Lattice {
  std::vector<Vec2f> x0, x, v, out;
  std::vector<float> speed;
};

// Agents at 0.9 rho_max on a square lattice filling the square of the given half width [m]
// centred in the grid, each walking to its centre.
Lattice lattice(const GridSpec<2>& g, double halfWidth) {
  Lattice l;
  const float h = static_cast<float>(1.0 / std::sqrt(0.9 * kRhoMax));
  const Vec2f c = (g.origin + 0.5 * g.extent()).cast<float>();
  const float w = static_cast<float>(halfWidth);
  for (float y = c.y() - w + h / 2; y < c.y() + w; y += h)
    for (float x = c.x() - w + h / 2; x < c.x() + w; x += h) {
      const Vec2f p(x, y), d = c - p;
      l.x0.push_back(p);
      l.v.push_back(d.norm() > 1e-3f ? Vec2f(d.normalized() * 1.4f) : Vec2f(1.4f, 0.0f));
    }
  l.x = l.x0;
  l.out.assign(l.x.size(), Vec2f::Zero());
  l.speed.assign(l.x.size(), 1.4f);
  return l;
}

void run(benchmark::State& state, const GridSpec<2>& g, Lattice& l) {
  UicSettings settings;
  settings.rhoMax = kRhoMax;
  UicProjection uic(g, settings);
  const Grid<float, 2> free(g, 1.0f);
  const Vec2f lo = g.origin.cast<float>(), hi = g.upper().cast<float>();
  double active = 0, iterations = 0, splat = 0, solve = 0, agents = 0;
  int step = 0;
  for (auto _ : state) {
    const UicStats& s = uic.project(l.x, l.v, l.speed, free, kDt, l.out);
    active += s.activeCells;
    iterations += s.innerIterations + s.outerIterations;
    splat += s.splatSeconds;
    solve += s.solveSeconds;
    agents += s.agentSeconds;
    state.PauseTiming();
    if (++step % kCycle == 0) {
      l.x = l.x0;
    } else {
      for (std::size_t i = 0; i < l.x.size(); ++i) l.x[i] = (l.x[i] + l.out[i] * float(kDt)).cwiseMax(lo).cwiseMin(hi);
    }
    state.ResumeTiming();
  }
  const double n = static_cast<double>(state.iterations());
  state.counters["agents"] = static_cast<double>(l.x.size());
  state.counters["active"] = active / n;
  state.counters["qp_iters"] = iterations / n;
  state.counters["splat_ms"] = 1e3 * splat / n;
  state.counters["solve_ms"] = 1e3 * solve / n;
  state.counters["agents_ms"] = 1e3 * agents / n;
}

void BM_UicCrowd(benchmark::State& state) {
  const int res = static_cast<int>(state.range(0));
  const GridSpec<2> g(Vec2(0, 0), kDx, IVec2(res, res));
  // Half width for the requested agent count at 0.9 rho_max.
  const double halfWidth = 0.5 * std::sqrt(static_cast<double>(state.range(1)) / (0.9 * kRhoMax));
  Lattice l = lattice(g, halfWidth);
  run(state, g, l);
}
// The 1M case runs exactly one reset cycle (the cost changes as the crowd compresses).
BENCHMARK(BM_UicCrowd)->Args({40, 10000})->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_UicCrowd)->Args({400, 1000000})->Iterations(kCycle)->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_UicActiveCells(benchmark::State& state) {
  const GridSpec<2> g(Vec2(0, 0), kDx, IVec2(128, 128));
  Lattice l = lattice(g, state.range(0) * kDx);
  run(state, g, l);
}
BENCHMARK(BM_UicActiveCells)->Arg(4)->Arg(8)->Arg(16)->Arg(32)->Arg(60)->Unit(benchmark::kMillisecond)->UseRealTime();

// Cost vs agent count at a fixed cell count: 128x128 grid, lattice of half width 16 cells, cell
// size dx = range / 10 m, so the agents per cell (0.9 rho_max dx^2) grow 16-fold from 1.5 to 6 m.
void BM_UicAgentsPerCell(benchmark::State& state) {
  const double dx = static_cast<double>(state.range(0)) / 10.0;
  const GridSpec<2> g(Vec2(0, 0), dx, IVec2(128, 128));
  Lattice l = lattice(g, 16 * dx);
  run(state, g, l);
}
BENCHMARK(BM_UicAgentsPerCell)->Arg(15)->Arg(30)->Arg(60)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
