// Multiple scattering (diffusion approximation, render/multiple_scattering) on a 128^3 smoke-like
// puff: a noisy ball lit from above, solved to relative residual 1e-3 from a cold start. The
// budget is the whole 128^3 render with multiple scattering in < 2 s on 2 cores. Counters:
// V-cycles, final residual, fraction of the cells holding medium.
#include <benchmark/benchmark.h>

#include <cmath>

#include "msim/core/rng.hpp"
#include "msim/render/multiple_scattering.hpp"

using namespace msim;
using namespace msim::render;

namespace {

constexpr int kRes = 128;

void BM_MultipleScattering(benchmark::State& state, double albedo) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / kRes, IVec3::Constant(kRes));
  const DiffusionMedium medium{30.0, albedo, 0.5};
  // Density: sqrt of a radial falloff to 0 at radius 0.4, times per-cell noise in [0.2, 1].
  Grid<float, 3> rho(spec), source(spec);
  Rng rng(1);
  std::size_t filled = 0;
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const double r = (rho.position(rho.coord(i)) - Vec3::Constant(0.5)).norm();
    rho[i] = static_cast<float>(std::sqrt(std::max(0.0, 1.0 - r / 0.4)) * rng.uniform(0.2, 1.0));
    filled += rho[i] > 1e-4f;
  }
  // First-scatter source of a unit directional light from above, Beer-Lambert to the cell centres.
  for (int k = 0; k < kRes; ++k)
    for (int i = 0; i < kRes; ++i) {
      double depth = 0.0;
      for (int j = kRes - 1; j >= 0; --j) {
        const IVec3 c(i, j, k);
        const double tau = medium.extinction * rho(c) * spec.dx;
        source(c) = static_cast<float>(albedo * medium.extinction * rho(c) * std::exp(-depth - 0.5 * tau));
        depth += tau;
      }
    }
  DiffusionSettings settings;
  settings.tolerance = 1e-3;
  DiffusionStats stats;
  for (auto _ : state) {
    Grid<float, 3> phi = solveMultipleScattering<3>(rho, source, medium, settings, &stats);
    benchmark::DoNotOptimize(phi.data().data());
  }
  state.counters["cycles"] = stats.cycles;
  state.counters["rel_residual"] = stats.relativeResidual;
  state.counters["medium_fraction"] = static_cast<double>(filled) / static_cast<double>(rho.count());
}

}  // namespace

BENCHMARK_CAPTURE(BM_MultipleScattering, puff_128_albedo_0_9, 0.9)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_MultipleScattering, puff_128_albedo_0_99, 0.99)->Unit(benchmark::kMillisecond)->UseRealTime();
