// The 3D smoke plume of scenes/plume_3d.json, and the ball of water falling into a pool of
// scenes/drop_into_pool.json (particle level set), stepped on a grid split among MPI processes
// (msim/parallel), through the phenomena exactly as `mpirun -np N msim run` does. Run under
// mpirun, e.g.
//   mpirun -np 1 build/release/bench/parallel_bench --benchmark_filter=Strong/r:336/threads:1
//   mpirun -np 2 build/release/bench/parallel_bench --benchmark_filter=Strong/r:336/threads:1
// Every rank times the same steps between barriers; rank 0 reports. Warm-up steps first, so the
// plume has risen and the pressure solve has work, and the water ball has hit the pool.
#include <benchmark/benchmark.h>
#include <mpi.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <memory>
#include <string>
#include <vector>

#include <fmt/format.h>

#include "msim/core/timer.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/scene/phenomenon.hpp"
#include "msim/scene/scene_file.hpp"

namespace {

using namespace msim;

// Steps of a scene with the given overrides after `warmUp` steps, one thread per process unless
// told otherwise; the step is the first one's (the plume), or the stable one of each (the liquid,
// which speeds up as the ball lands).
void runScene(benchmark::State& state, const std::string& scene, const std::vector<std::string>& overrides,
              int threadCount, int warmUp, bool stableEachStep) {
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threadCount));
  const scene::Scene s = scene::loadScene(std::string(MSIM_SOURCE_DIR) + "/scenes/" + scene, overrides);
  StageTimers timers;
  const std::unique_ptr<scene::Phenomenon> phenomenon = s.type->create(s, timers);
  const double first = std::min(phenomenon->stableTimestep(), 1.0 / s.fps);
  const auto step = [&] { return stableEachStep ? std::min(phenomenon->stableTimestep(), 1.0 / s.fps) : first; };
  for (int k = 0; k < warmUp; ++k) phenomenon->step(step());
  timers.reset();
  for (auto _ : state) {
    const double dt = step();
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = MPI_Wtime();
    phenomenon->step(dt);
    MPI_Barrier(MPI_COMM_WORLD);
    state.SetIterationTime(MPI_Wtime() - start);
  }
  // Each stage's seconds per step on this process (rank 0's are reported): where the time goes.
  for (const StageTime& t : timers.table())
    state.counters[t.name] = benchmark::Counter(t.seconds / double(state.iterations()));
  state.counters["ranks"] = parallel::worldSize();
  state.counters["cells_per_rank"] = static_cast<double>(s.cellCount()) / parallel::worldSize();
}

void runPlume(benchmark::State& state, const std::vector<std::string>& overrides, int threadCount) {
  runScene(state, "plume_3d.json", overrides, threadCount, 2, false);
}

// Strong scaling: the plume at `r` cells along its tallest axis (2/3 r x r x 2/3 r cells: r = 336
// is 16.9M cells, as many as 256^3), whatever the process count.
void BM_Strong(benchmark::State& state) {
  runPlume(state, {fmt::format("domain.resolution={}", state.range(0))}, static_cast<int>(state.range(1)));
}
BENCHMARK(BM_Strong)
    ->ArgsProduct({{64, 128, 336}, {1, 2}})
    ->ArgNames({"r", "threads"})
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

// Weak scaling: the domain grows along z with the process count, n^3 cells per unit of depth
// (n x 1.5 n x n cells per process), one thread each.
void BM_Weak(benchmark::State& state) {
  const int ranks = parallel::worldSize(), n = static_cast<int>(state.range(0));
  const double depth = ranks;
  runPlume(state,
           {fmt::format("domain.max=[1.0,1.5,{}]", depth),
            fmt::format("domain.resolution={}", static_cast<int>(n * std::max(1.5, depth)))},
           1);
}
BENCHMARK(BM_Weak)->Arg(96)->ArgName("n")->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

// The liquid: a ball of water falling into a pool at r^3 cells (r = 48 is the scene's own grid),
// 20 steps after the start (the ball has hit the pool: the surface, its particles and the
// pressure's free surface all have work), whatever the process count.
void BM_LiquidStrong(benchmark::State& state) {
  runScene(state, "drop_into_pool.json", {fmt::format("domain.resolution={}", state.range(0))},
           static_cast<int>(state.range(1)), 20, true);
}
BENCHMARK(BM_LiquidStrong)
    ->ArgsProduct({{48, 96}, {1, 2}})
    ->ArgNames({"r", "threads"})
    ->UseManualTime()
    ->Iterations(5)
    ->Unit(benchmark::kMillisecond);

// Reports nothing: the ranks other than 0 run the same steps silently.
class SilentReporter : public benchmark::BenchmarkReporter {
 public:
  bool ReportContext(const Context&) override { return true; }
  void ReportRuns(const std::vector<Run>&) override {}
};

}  // namespace

int main(int argc, char** argv) {
  parallel::MpiSession mpi(argc, argv);
  benchmark::Initialize(&argc, argv);
  if (parallel::worldRank() == 0) {
    benchmark::RunSpecifiedBenchmarks();
  } else {
    SilentReporter silent;
    benchmark::RunSpecifiedBenchmarks(&silent);
  }
  benchmark::Shutdown();
  return 0;
}
