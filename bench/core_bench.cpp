// Throughput of the core particle/grid transfers and point interpolation on a 128^3 grid.
#include <benchmark/benchmark.h>

#include <vector>

#include "msim/core/interpolation.hpp"
#include "msim/core/rng.hpp"
#include "msim/core/transfer.hpp"

using namespace msim;

namespace {

constexpr int kRes = 128;
constexpr std::size_t kParticles = 1'000'000;

const GridSpec<3>& spec() {
  static const GridSpec<3> s(Vec3::Zero(), 1.0 / kRes, IVec3::Constant(kRes));
  return s;
}

const std::vector<Vecf<3>>& positions() {
  static const std::vector<Vecf<3>> p = [] {
    Rng rng(1);
    std::vector<Vecf<3>> out(kParticles);
    for (auto& x : out) x = Vecf<3>(float(rng.uniform()), float(rng.uniform()), float(rng.uniform()));
    return out;
  }();
  return p;
}

const Grid<float, 3>& field() {
  static const Grid<float, 3> g = [] {
    Rng rng(2);
    Grid<float, 3> out(spec());
    for (float& v : out.data()) v = float(rng.uniform());
    return out;
  }();
  return g;
}

TransferKernel kernelArg(const benchmark::State& state) {
  return state.range(0) == 0 ? TransferKernel::Linear : TransferKernel::QuadraticBSpline;
}

void BM_Splat(benchmark::State& state) {
  const std::vector<float> values(kParticles, 1.0f);
  Grid<float, 3> target(spec());
  Splatter<3> splatter;
  const auto mode = state.range(1) == 0 ? SplatMode::Sum : SplatMode::Normalized;
  for (auto _ : state) {
    splatter.splat(positions(), values, target, kernelArg(state), mode);
    benchmark::DoNotOptimize(target.data().data());
  }
  state.SetItemsProcessed(state.iterations() * kParticles);
  state.SetLabel(state.range(0) == 0 ? "linear" : "quadratic");
}
BENCHMARK(BM_Splat)->ArgsProduct({{0, 1}, {0, 1}})->ArgNames({"kernel", "normalized"})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_Gather(benchmark::State& state) {
  std::vector<float> out(kParticles);
  for (auto _ : state) {
    gather<3>(field(), positions(), kernelArg(state), out);
    benchmark::DoNotOptimize(out.data());
  }
  state.SetItemsProcessed(state.iterations() * kParticles);
  state.SetLabel(state.range(0) == 0 ? "linear" : "quadratic");
}
BENCHMARK(BM_Gather)->Arg(0)->Arg(1)->ArgName("kernel")->Unit(benchmark::kMillisecond)->UseRealTime();

// Single-threaded point sampling, the inner operation of semi-Lagrangian advection.
void BM_SampleLinear(benchmark::State& state) {
  const Grid<float, 3>& g = field();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Vecf<3>& p : positions()) sum += sampleLinear<3>(g, p.cast<double>());
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kParticles);
}
BENCHMARK(BM_SampleLinear)->Unit(benchmark::kMillisecond);

void BM_SampleMonotoneCubic(benchmark::State& state) {
  const Grid<float, 3>& g = field();
  for (auto _ : state) {
    double sum = 0.0;
    for (const Vecf<3>& p : positions()) sum += sampleMonotoneCubic<3>(g, p.cast<double>());
    benchmark::DoNotOptimize(sum);
  }
  state.SetItemsProcessed(state.iterations() * kParticles);
}
BENCHMARK(BM_SampleMonotoneCubic)->Unit(benchmark::kMillisecond);

}  // namespace
