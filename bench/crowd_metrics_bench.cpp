// The crowd's per-frame Voronoi metrics (Steffen & Seyfried 2010): the clipped Voronoi cells of
// N agents placed uniformly at random at 2 agents/m^2 (the neighbours from Boost.Polygon's Voronoi
// diagram, the cells by half-plane clipping), and their densities.
#include <benchmark/benchmark.h>

#include <cmath>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/crowd/voronoi_density.hpp"

using namespace msim;
using crowd::Vec2f;

namespace {

void BM_VoronoiCells(benchmark::State& state) {
  const auto n = static_cast<std::size_t>(state.range(0));
  const double side = std::sqrt(static_cast<double>(n) / 2.0);
  Rng rng(11);
  std::vector<Vec2f> positions(n);
  for (Vec2f& x : positions) x = Vec2f(static_cast<float>(side * rng.uniform()), static_cast<float>(side * rng.uniform()));
  crowd::VoronoiOptions options;
  options.domainLo = Vec2::Zero();
  options.domainHi = Vec2::Constant(side);
  for (auto _ : state) {
    const crowd::VoronoiCells cells = crowd::voronoiCells(positions, options);
    benchmark::DoNotOptimize(crowd::voronoiDensity(cells).data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_VoronoiCells)->Arg(10000)->Arg(100000)->Unit(benchmark::kMillisecond);

}  // namespace
