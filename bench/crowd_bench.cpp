// Whole crowd steps (Narain 2011 ch. 4.4.4: planning, UIC projection, agent motion, pairwise
// resolution, exits and inflows) of the scene files, as `msim run` steps them, without the frame
// outputs. Table 4.1 scenes at their grids and agent counts, and the scaling curve of Fig. 4.11:
// the circle of Fig. 4.5 grown to N agents at the same density and cell size, walked by UIC agents
// and by ORCA agents (its first steps, and at 100k its first 20 s averaged).
#include <benchmark/benchmark.h>

#include <cmath>
#include <cstdlib>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>
#include <tbb/global_control.h>

#include "msim/core/timer.hpp"
#include "msim/scene/scene_file.hpp"

using namespace msim;

namespace {

// CROWD_BENCH_THREADS=k limits the TBB workers (k = 1: the work per step, steadier on a shared
// machine than the wall time over two cores).
const std::unique_ptr<tbb::global_control> kThreads = [] {
  const char* k = std::getenv("CROWD_BENCH_THREADS");
  return k ? std::make_unique<tbb::global_control>(tbb::global_control::max_allowed_parallelism, std::atoi(k))
           : nullptr;
}();

std::string scenePath(const std::string& name) { return std::string(MSIM_SOURCE_DIR) + "/scenes/" + name + ".json"; }

// Runs `warmup` steps, then times steps; counters: agents and seconds per step of each stage.
void stepScene(benchmark::State& state, const std::string& file, const std::vector<std::string>& overrides, int warmup) {
  const scene::Scene s = scene::loadScene(file, overrides);
  StageTimers timers;
  auto phenomenon = s.type->create(s, timers);
  for (int k = 0; k < warmup; ++k) phenomenon->step(phenomenon->stableTimestep());
  timers.reset();
  for (auto _ : state) phenomenon->step(phenomenon->stableTimestep());
  for (const auto& stage : timers.table())
    state.counters[stage.name] = stage.seconds / static_cast<double>(state.iterations());
  state.counters["agents"] = phenomenon->statistics().at("agents").get<double>();
}

// Table 4.1. The circle is measured while the crowd is densest (t = 15-25 s: they meet in the
// middle); the others after enough steps for their crowds to form queues.
void BM_Circle10k(benchmark::State& state) { stepScene(state, scenePath("crowd_circle"), {}, 150); }
void BM_Crossing(benchmark::State& state) { stepScene(state, scenePath("crowd_crossing"), {}, 400); }
void BM_Building2k(benchmark::State& state) { stepScene(state, scenePath("crowd_building"), {}, 100); }
void BM_TradeShow80k(benchmark::State& state) { stepScene(state, scenePath("crowd_trade_show"), {}, 20); }
void BM_Campsite100k(benchmark::State& state) { stepScene(state, scenePath("crowd_campsite"), {}, 20); }
void BM_Mosque25k(benchmark::State& state) { stepScene(state, scenePath("crowd_mosque"), {}, 50); }
// The same scenes with the default model's walking speeds (the scene files keep the seed's constant
// speeds for its figures): its cost against Table 4.1's.
const std::vector<std::string> kDefaultModel = {"crowd.uic.speed_density=weidmann"};
void BM_Circle10kDefaultModel(benchmark::State& state) { stepScene(state, scenePath("crowd_circle"), kDefaultModel, 150); }
void BM_TradeShow80kDefaultModel(benchmark::State& state) {
  stepScene(state, scenePath("crowd_trade_show"), kDefaultModel, 20);
}

// Fig. 4.11: the circle with N agents (range 0, thousands), the disc and the domain grown by
// sqrt(N / 10k) so density and cell size (2.5 m) stay those of the 10k scene; range 1 picks the
// model (0 UIC, 1 ORCA). Timed from the start: at 1M agents the fronts need minutes to meet.
std::vector<std::string> scaledCircle(const benchmark::State& state) {
  const double n = 1000.0 * static_cast<double>(state.range(0));
  const double scale = std::sqrt(n / 10000.0);
  return {fmt::format("domain.max=[{},{}]", 100 * scale, 100 * scale),
          fmt::format("domain.resolution={}", static_cast<int>(std::lround(40 * scale))),
          fmt::format("groups[0].count={}", static_cast<long long>(n)),
          fmt::format("groups[0].region.center=[{},{}]", 50 * scale, 50 * scale),
          fmt::format("groups[0].region.radius={}", 40 * scale),
          std::string("groups[0].model=") + (state.range(1) == 0 ? "uic" : "orca")};
}

void BM_CircleScaling(benchmark::State& state) { stepScene(state, scenePath("crowd_circle"), scaledCircle(state), 2); }

// Runs the first `steps` steps of `s` from its start once per iteration; counters: each stage's
// seconds per step and the time per step.
void runFromStart(benchmark::State& state, const scene::Scene& s, int steps) {
  for (auto _ : state) {
    state.PauseTiming();
    StageTimers timers;
    auto phenomenon = s.type->create(s, timers);
    timers.reset();  // the stage counters per step, without the first frame's metrics
    state.ResumeTiming();
    for (int k = 0; k < steps; ++k) phenomenon->step(phenomenon->stableTimestep());
    state.PauseTiming();
    for (const auto& stage : timers.table()) state.counters[stage.name] = stage.seconds / steps;
    state.ResumeTiming();
  }
  state.counters["per_step"] = benchmark::Counter(steps, benchmark::Counter::kIsIterationInvariantRate |
                                                             benchmark::Counter::kInvert);
}

// The same circle timed over its first 200 steps (20 s: the disc closes in and the crowd packs to
// rho_max), one run per iteration, the average per step reported; range as above.
void BM_CircleScalingRun(benchmark::State& state) {
  runFromStart(state, scene::loadScene(scenePath("crowd_circle"), scaledCircle(state)), 200);
}

// Golas Table 3.1's four-way crossing (2000 ORCA agents) while the four groups meet (after 20 s),
// by method: range 0 plain ORCA (Disc), 1 discrete lookahead (Disc LA), 2 continuum (Cont LA),
// 3 hybrid (Hyb LA); 8 levels. Ranges 4 and 5 are 1 and 3 with the discrete cascade (the far
// levels solved apart every second, their answer ORCA's preferred velocity).
void BM_LookaheadFourWay(benchmark::State& state) {
  static const char* kMethods[] = {"discrete", "discrete", "continuum", "hybrid", "discrete", "hybrid"};
  const auto method = static_cast<std::size_t>(state.range(0));
  stepScene(state, scenePath("crowd_lookahead_four_way"),
            {fmt::format("crowd.lookahead.levels={}", method == 0 ? 0 : 8), std::string("crowd.lookahead.method=") + kMethods[method],
             std::string("crowd.lookahead.discrete_solve=") + (method >= 4 ? "cascade" : "single")},
            400);
}
// Table 3.1's four groups (2000 UIC agents) while they meet (after 30 s): range 0 the continuum
// alone (Cont), 1 with the continuum lookahead (Cont LA), its far levels asked every 0.5 s.
void BM_LookaheadFourGroups(benchmark::State& state) {
  stepScene(state, scenePath("crowd_lookahead_four_groups"),
            {fmt::format("crowd.lookahead.levels={}", state.range(0) == 0 ? 0 : 8)}, 600);
}
// The circle of Fig. 4.11 at 100k UIC agents (as BM_CircleScalingRun), with the continuum
// lookahead of crowd_lookahead_four_groups (range 1) or without (0): its first 200 steps.
void BM_LookaheadCircle100k(benchmark::State& state) {
  std::vector<std::string> overrides = {"domain.max=[316.2,316.2]", "domain.resolution=126", "groups[0].count=100000",
                                        "groups[0].region.center=[158.1,158.1]", "groups[0].region.radius=126.5"};
  if (state.range(0) == 1)
    for (const char* o : {"crowd.lookahead.levels=8", "crowd.lookahead.base_step=0.2", "crowd.lookahead.coarsening=1.414",
                          "crowd.lookahead.cell=0.5"})
      overrides.emplace_back(o);
  runFromStart(state, scene::loadScene(scenePath("crowd_circle"), overrides), 200);
}

// Golas ch. 4's stress model on scenes/crowd_stress_merge.json once its crowd has packed (after
// 40 s of 0.01 s steps, about 1250 agents): the midpoint step's two friction solves are the
// `crowd: stress` counter.
void BM_StressMerge(benchmark::State& state) { stepScene(state, scenePath("crowd_stress_merge"), {}, 4000); }
// The issue's size: the merge held at 6800 agents (5.8 /m^2) by recycling inflows, as the Hajj
// sweep of docs/crowd_turbulence.md, after 10 s; range: the cells per metre (1: the scene's 1 m
// cells, 2: 0.5 m cells).
void BM_StressMerge6800(benchmark::State& state) {
  stepScene(state, scenePath("crowd_stress_merge"),
            {R"(groups=[{"count": 6800, "region": {"type": "box", "min": [0, 0], "max": [50, 30]}, "goal": "out"}])",
             R"(inflows=[{"region": {"type": "box", "min": [0.5, 18.5], "max": [3, 27.5]}, "rate": 0, "recycle": true, "goal": "out"},
                         {"region": {"type": "box", "min": [0.5, 2.5], "max": [3, 11.5]}, "rate": 0, "recycle": true, "goal": "out"}])",
             fmt::format("domain.resolution={}", 50 * state.range(0))},
            1000);
}

}  // namespace

BENCHMARK(BM_StressMerge)->Unit(benchmark::kMillisecond)->Iterations(100);
BENCHMARK(BM_StressMerge6800)->DenseRange(1, 2)->Unit(benchmark::kMillisecond)->Iterations(100);
BENCHMARK(BM_LookaheadFourWay)->DenseRange(0, 5)->Unit(benchmark::kMillisecond)->Iterations(100);
BENCHMARK(BM_LookaheadFourGroups)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->Iterations(200);
BENCHMARK(BM_LookaheadCircle100k)->DenseRange(0, 1)->Unit(benchmark::kMillisecond)->Iterations(1);
BENCHMARK(BM_Circle10k)->Unit(benchmark::kMillisecond)->Iterations(100);
BENCHMARK(BM_Crossing)->Unit(benchmark::kMillisecond)->Iterations(50);
BENCHMARK(BM_Building2k)->Unit(benchmark::kMillisecond)->Iterations(50);
BENCHMARK(BM_Mosque25k)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_TradeShow80k)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_Campsite100k)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_Circle10kDefaultModel)->Unit(benchmark::kMillisecond)->Iterations(100);
BENCHMARK(BM_TradeShow80kDefaultModel)->Unit(benchmark::kMillisecond)->Iterations(10);
BENCHMARK(BM_CircleScaling)
    ->ArgsProduct({{10, 30, 100, 300, 1000}, {0, 1}})
    ->Unit(benchmark::kMillisecond)
    ->Iterations(5);
BENCHMARK(BM_CircleScalingRun)->ArgsProduct({{100}, {0, 1}})->Unit(benchmark::kMillisecond)->Iterations(1);
