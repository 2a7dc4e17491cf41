// Turbulent wind (Stam ch. 3.4): synthesis of the periodic 4D lattice (3 inverse FFTs of
// M^3 x M_t complex samples), and sampling it on a grid's faces every step (gas and smoke winds)
// and at scattered points. Procedural sub-grid turbulence in smoke (Narain ch. 3): one step.
#include <benchmark/benchmark.h>

#include <cmath>

#include "msim/core/mac_grid.hpp"
#include "msim/core/rng.hpp"
#include "msim/fluid/smoke/smoke_turbulence.hpp"
#include "msim/turbulence/curl_noise.hpp"
#include "msim/turbulence/turbulent_wind.hpp"

using namespace msim;

namespace {

turbulence::SpectralWindParams lattice(int m, int mt) {
  turbulence::SpectralWindParams p;
  p.resolution = m;
  p.timeSamples = mt;
  p.spectrum.largestEddy = 0.25;
  p.spectrum.smallestEddy = 2.0 / m;
  return p;
}

void BM_WindSynthesis(benchmark::State& state) {
  const auto p = lattice(static_cast<int>(state.range(0)), static_cast<int>(state.range(1)));
  for (auto _ : state) benchmark::DoNotOptimize(turbulence::SpectralWind<3>(p).samples().data());
  state.counters["samples"] = static_cast<double>(std::pow(p.resolution, 3) * p.timeSamples);
}
BENCHMARK(BM_WindSynthesis)->Args({16, 16})->Args({32, 16})->Args({64, 16})->Unit(benchmark::kMillisecond);

// All three face components of an n^3 MAC grid, as GasSolver::addWind resamples every step.
void BM_WindOnFaces(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const turbulence::TurbulentWind<3> wind(turbulence::SpectralWind<3>(lattice(32, 16)), Vec3::Zero(), Vec3(0.3, 0, 0));
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3(n, n, n));
  MacGrid<3> u(spec);
  double t = 0.0;
  for (auto _ : state) {
    for (int a = 0; a < 3; ++a) {
      auto& g = u.component(a);
      wind.forEachSample(g, a, t, [&](std::size_t lin, float v) { g[lin] = v; });
    }
    t += 0.01;
  }
  const double faces = 3.0 * std::pow(n, 3);
  state.counters["time/face"] =
      benchmark::Counter(faces, benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_WindOnFaces)->Arg(64)->Arg(128)->Unit(benchmark::kMillisecond);

// velocity(x, t) at scattered points (quadrilinear, 16 samples).
void BM_WindAtPoints(benchmark::State& state) {
  const turbulence::TurbulentWind<3> wind(turbulence::SpectralWind<3>(lattice(32, 16)), Vec3::Zero(), Vec3::Zero());
  Rng rng(1);
  std::vector<Vec3> points(1 << 16);
  for (auto& x : points) x = Vec3(rng.uniform(), rng.uniform(), rng.uniform());
  double t = 0.0;
  for (auto _ : state) {
    Vec3 sum = Vec3::Zero();
    for (const Vec3& x : points) sum += wind.velocity(x, t);
    benchmark::DoNotOptimize(sum);
    t += 0.01;
  }
  state.counters["time/point"] = benchmark::Counter(static_cast<double>(points.size()),
                                                  benchmark::Counter::kIsIterationInvariantRate | benchmark::Counter::kInvert);
}
BENCHMARK(BM_WindAtPoints)->Unit(benchmark::kMillisecond);

// The vector noise read as the synthesis reads it: runs of nodes along a row a fine cell apart
// (1/16 noise unit for octave 0 with l_0 = 16 fine cells) from random starts and times.
void BM_NoiseTileLookup(benchmark::State& state) {
  const turbulence::NoiseTile<3> tile(1);
  Rng rng(7);
  constexpr int kRun = 32, kRuns = 1024;
  std::vector<Vec3> start(kRuns);
  std::vector<LinearTap> time(kRuns);
  for (int r = 0; r < kRuns; ++r) {
    start[r] = Vec3(rng.uniform(0.0, 4.0), rng.uniform(0.0, 4.0), rng.uniform(0.0, 4.0));
    time[r] = tile.timeTap(rng.uniform(0.0, 8.0));
  }
  for (auto _ : state) {
    Vecf<3> sum = Vecf<3>::Zero();
    for (int r = 0; r < kRuns; ++r) {
      const auto row = tile.row(start[r], time[r]);
      for (int k = 0; k < kRun; ++k) sum += tile.onRow(row, start[r].x() + k / 16.0);
    }
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kRuns * kRun);
}
BENCHMARK(BM_NoiseTileLookup)->Unit(benchmark::kMicrosecond);

}  // namespace

namespace {

// One step of procedural turbulence in smoke (energy model, noise particles, u' near the smoke,
// fine scalars by U + u'): a rising column on n x 4n x n simulation cells, 4x finer smoke.
void BM_SmokeTurbulenceStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  const GridSpec<3> coarse(Vec3::Zero(), 1.0 / (4 * n), IVec3(n, 4 * n, n));
  fluid::SmokeTurbulence<3> turbulence(coarse, fluid::SmokeTurbulenceParams{}, numerics::AdvectionSettings{}, nullptr,
                                       293.15);
  // Smoke in a column a quarter of the width across, rising at 0.5 m/s with a shear round it.
  MacGrid<3> u(coarse);
  auto& uy = u.component(1);
  for (std::size_t i = 0; i < uy.count(); ++i) {
    const Vec3 x = uy.position(uy.coord(i));
    const double r = std::hypot(x.x() - 0.125, x.z() - 0.125);
    uy[i] = static_cast<float>(0.5 * std::exp(-r * r / (2 * 0.03 * 0.03)));
  }
  Grid<float, 3> rho(coarse, 0.0f), temperature(coarse, 293.15f);
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const Vec3 x = rho.position(rho.coord(i));
    if (std::hypot(x.x() - 0.125, x.z() - 0.125) < 0.03) rho[i] = 1.0f;
  }
  auto& fine = turbulence.density();
  for (std::size_t i = 0; i < fine.count(); ++i) {
    const Vec3 x = fine.position(fine.coord(i));
    if (std::hypot(x.x() - 0.125, x.z() - 0.125) < 0.03) fine[i] = 1.0f;
  }
  const double dt = coarse.dx / 0.5;
  for (auto _ : state) turbulence.step(u, dt, rho, temperature);
  state.counters["fine_cells"] = static_cast<double>(fine.count());
  state.counters["band"] = turbulence.bandFraction();
  state.counters["particles"] = static_cast<double>(turbulence.particles().size());
}
BENCHMARK(BM_SmokeTurbulenceStep)->Arg(16)->Arg(32)->Unit(benchmark::kMillisecond)->Iterations(5);

}  // namespace
