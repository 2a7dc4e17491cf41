// Local interaction at scale (Narain 2011, ch. 4.5.1: collision resolution is the per-agent cost
// that dominates at 1M agents; the RVO baseline failed past 70k). Dense random layout: agents of
// radius 0.25 m at 2 agents/m^2 (~40% area fraction) in a square, random unit headings.
#include <cmath>
#include <cstdlib>
#include <memory>
#include <random>
#include <vector>

#include <benchmark/benchmark.h>
#include <tbb/global_control.h>

#include "msim/crowd/collision_resolution.hpp"
#include "msim/crowd/lookahead/agent_lookahead.hpp"
#include "msim/crowd/orca.hpp"
#include "msim/crowd/walking_density.hpp"

namespace {

using namespace msim::crowd;

// CROWD_BENCH_THREADS=k limits the TBB workers (on a loaded machine, k = 1 gives the work per
// call, the CPU-time column then being the whole cost).
const std::unique_ptr<tbb::global_control> kThreads = [] {
  const char* k = std::getenv("CROWD_BENCH_THREADS");
  return k ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::atoi(k))
           : nullptr;
}();

Agents denseCrowd(std::size_t n, AgentModel model) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  const float side = std::sqrt(static_cast<float>(n) / 2.0f);
  Agents a;
  a.reserve(n);
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec s;
    s.position = Vec2f(side * u(rng), side * u(rng));
    s.model = model;
    const std::size_t k = a.add(s);
    const float phi = 6.2831853f * u(rng);
    a.preferredVelocity[k] = 1.2f * Vec2f(std::cos(phi), std::sin(phi));
    a.velocity[k] = a.preferredVelocity[k];
  }
  return a;
}

// From uniformly random positions: the worst case (deep overlaps everywhere, agents move far
// and the buckets are redone during the sweeps).
void BM_CollisionResolution(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Agents start = denseCrowd(n, AgentModel::Uic);
  const float side = std::sqrt(static_cast<float>(n) / 2.0f);
  const DomainBox domain{Vec2f(-1, -1), Vec2f(side + 1, side + 1)};
  CollisionResolver resolver;
  Agents a = start;
  resolver.resolve(a, StaticObstacles(), domain);  // warm: grids and buffers allocated
  for (auto _ : state) {
    state.PauseTiming();
    a.position = start.position;
    state.ResumeTiming();
    resolver.resolve(a, StaticObstacles(), domain);  // defaults: separation 1.2, 6 Gauss-Seidel sweeps
  }
  state.counters["bucketings"] = resolver.lastBucketings();
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_CollisionResolution)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();

// One simulation step's worth: a resolved crowd whose agents then walked 0.1 s at their preferred
// velocities (1.2 m/s, random headings), which is what resolve() sees after each step.
void BM_CollisionResolutionStep(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  CollisionResolutionParams params;  // range(1): 0 Gauss-Seidel, 1 Jacobi; range(2): sweeps
  params.sweeps = state.range(1) ? CollisionResolutionParams::Sweeps::Jacobi : CollisionResolutionParams::Sweeps::GaussSeidel;
  params.iterations = static_cast<int>(state.range(2));
  Agents start = denseCrowd(n, AgentModel::Uic);
  const float side = std::sqrt(static_cast<float>(n) / 2.0f);
  const DomainBox domain{Vec2f(-1, -1), Vec2f(side + 1, side + 1)};
  CollisionResolver resolver;
  CollisionResolutionParams settle;
  settle.iterations = 40;
  resolver.resolve(start, StaticObstacles(), domain, settle);
  for (std::size_t i = 0; i < n; ++i) start.position[i] += 0.1f * start.preferredVelocity[i];
  Agents a = start;
  resolver.resolve(a, StaticObstacles(), domain, params);  // warm
  for (auto _ : state) {
    state.PauseTiming();
    a.position = start.position;
    state.ResumeTiming();
    resolver.resolve(a, StaticObstacles(), domain, params);
  }
  state.counters["bucketings"] = resolver.lastBucketings();
  state.counters["sweeps"] = resolver.lastSweeps();
  state.counters["local"] = resolver.lastLocalSweeps();
  state.counters["redone"] = resolver.lastRedoneSweeps();
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
BENCHMARK(BM_CollisionResolutionStep)
    ->ArgsProduct({{10'000, 100'000, 1'000'000}, {0, 1}, {6, 12}})->Unit(benchmark::kMillisecond)->UseRealTime();

void BM_OrcaStep(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Agents a = denseCrowd(n, AgentModel::Orca);
  OrcaSolver solver;
  OrcaParams params;
  params.neighbourDist = 2.0f;
  std::vector<Vec2f> v(n);
  solver.computeVelocities(a, StaticObstacles(), params, 0.1f, v);  // warm
  for (auto _ : state) {
    solver.computeVelocities(a, StaticObstacles(), params, 0.1f, v);
    benchmark::DoNotOptimize(v.data());
  }
  state.SetItemsProcessed(state.iterations() * static_cast<std::int64_t>(n));
}
// The discrete lookahead (Golas ch. 3.6) in a four-way crossing of 4 x n/4 ORCA agents: four
// blocks of 25 x 10 m at the sides of a 60 m square walking at 1.4 m/s towards the opposite
// side, met halfway; range(1) levels of 0.01 s (0: plain ORCA). A step is the depths, the cluster
// tree and the velocities; the seed (Table 3.1, one 2008 core): 21 steps/s with 2000 agents.
void BM_OrcaLookahead(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const int levels = static_cast<int>(state.range(1));
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  Agents a;
  a.reserve(n);
  const Vec2f centre(30.0f, 30.0f);
  for (std::size_t i = 0; i < n; ++i) {
    const int side = static_cast<int>(i % 4);
    const Vec2f across = side % 2 == 0 ? Vec2f(1.0f, 0.0f) : Vec2f(0.0f, 1.0f);
    const Vec2f along = side % 2 == 0 ? Vec2f(0.0f, 1.0f) : Vec2f(1.0f, 0.0f);
    const float sign = side < 2 ? -1.0f : 1.0f;
    AgentSpec spec;
    spec.model = AgentModel::Orca;
    spec.position = centre + sign * (7.0f + 10.0f * u(rng)) * across + (25.0f * u(rng) - 12.5f) * along;
    const std::size_t k = a.add(spec);
    a.preferredVelocity[k] = -sign * 1.4f * across;
    a.velocity[k] = a.preferredVelocity[k];
  }
  OrcaSolver solver;
  OrcaParams params;
  lookahead::LookaheadSettings settings;
  settings.levels = levels;
  settings.baseStep = 0.01;
  lookahead::AgentLookahead ahead(settings);
  const StaticObstacles none;
  std::vector<Vec2f> v(n);
  for (auto _ : state) {
    const lookahead::DiscreteLookahead* la = levels > 0 ? &ahead.prepare(a, none, params.neighbourDist, 1.4, msim::Vec2::Zero(), msim::Vec2::Zero(), {.tree = true}) : nullptr;
    solver.computeVelocities(a, none, params, 0.01f, v, la);
    benchmark::DoNotOptimize(v.data());
  }
  state.counters["steps_per_s"] = benchmark::Counter(static_cast<double>(state.iterations()), benchmark::Counter::kIsRate);
}
BENCHMARK(BM_OrcaLookahead)->Args({2000, 0})->Args({2000, 8})->Unit(benchmark::kMillisecond)->UseRealTime();

// The default model's walking speeds (walking_density.hpp): the neighbour grid of everyone and the
// count of the others in each agent's square ahead, at 2 agents/m^2.
void BM_WalkingSpeeds(benchmark::State& state) {
  const std::size_t n = static_cast<std::size_t>(state.range(0));
  const Agents a = denseCrowd(n, AgentModel::Uic);
  const float side = std::sqrt(static_cast<float>(n) / 2.0f);
  WalkingDensity walking(msim::Vec2(-1, -1), msim::Vec2(side + 1, side + 1), {}, {});
  std::vector<float> density(n), speed(n);
  for (auto _ : state) {
    walking.measure(a.position, a.preferredVelocity, a.maxSpeed, density, speed);
    benchmark::DoNotOptimize(speed.data());
  }
}

BENCHMARK(BM_WalkingSpeeds)->Arg(10'000)->Arg(100'000)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_OrcaStep)->Arg(10'000)->Arg(100'000)->Arg(1'000'000)->Unit(benchmark::kMillisecond)->UseRealTime();

}  // namespace
