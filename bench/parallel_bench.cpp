// A 3D smoke step split among MPI processes (msim/parallel): run under mpirun, e.g.
//   mpirun -np 1 build/release/bench/parallel_bench --benchmark_filter=/256/1
//   mpirun -np 2 build/release/bench/parallel_bench --benchmark_filter=/256/1
// BM_SplitSmokeStep (strong scaling): the grid's cells per axis and oneTBB threads per process;
// BM_SplitSmokeStepWeak: n^3 cells per process (the grid grows along z), one thread each. Every rank times
// the same steps between barriers; rank 0 reports. The plume is the one of the distributed smoke
// test (hot smoke with inflow, buoyancy, vorticity confinement, MacCormack, open top), warmed up
// for two steps so the pressure solve has work.
#include <benchmark/benchmark.h>
#include <mpi.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <memory>

#include "msim/fluid/smoke/smoke_solver.hpp"
#include "msim/parallel/ghost_layers.hpp"
#include "msim/parallel/mpi_domain_split.hpp"
#include "msim/parallel/mpi_session.hpp"

namespace {

using namespace msim;

fluid::SmokeParams<3> plumeParams() {
  fluid::SmokeParams<3> p;
  p.sides.side[1][1] = numerics::DomainSide::Open;
  p.buoyancy.alpha = 0.02;
  p.buoyancy.beta = 0.04;
  p.vorticityEpsilon = 0.2;
  return p;
}

fluid::SmokeSource<3> plumeSource(const GridSpec<3>& spec) {
  fluid::SmokeSource<3> src;
  src.density = 1.0;
  src.temperature = 420.0;
  src.velocity = Vec<3>(0.0, 1.0, 0.0);
  Grid<float, 3> cells(spec);
  for (std::size_t i = 0; i < cells.count(); ++i) {
    const double d = (cells.position(cells.coord(i)) - Vec<3>(0.5, 0.15, 0.5)).norm() - 0.12;
    const double coverage = std::clamp(0.5 - d / spec.dx, 0.0, 1.0);
    if (coverage > 0.0) src.cells.emplace_back(i, static_cast<float>(coverage));
  }
  return src;
}

// Steps of the plume on `global`, split among the ranks; time per step between barriers.
void runSplitSmoke(benchmark::State& state, const GridSpec<3>& global, int threadCount) {
  const int n = global.res.minCoeff();
  tbb::global_control threads(tbb::global_control::max_allowed_parallelism, static_cast<std::size_t>(threadCount));
  const fluid::SmokeParams<3> params = plumeParams();
  const int ghost = parallel::smokeGhostLayers(params.advection, 1.0);
  const parallel::GridBlock<3> block(
      global, parallel::BlockDecomposition<3>(global.res, parallel::worldSize(), ghost, "bench"),
      parallel::worldRank(), ghost);
  parallel::MpiDomainSplit split(block, params.sides, params.projection.pcg, MPI_COMM_WORLD);
  fluid::SmokeSolver<3> solver(block.localSpec(), params);
  solver.addSource(plumeSource(block.localSpec()));
  solver.setDomainSplit(&split);
  const double dt = 0.5 / n;  // half a cell per step at 1 m/s
  for (int s = 0; s < 2; ++s) solver.step(dt);
  const std::size_t bytesBefore = split.receivedGhostBytes();
  for (auto _ : state) {
    MPI_Barrier(MPI_COMM_WORLD);
    const double start = MPI_Wtime();
    solver.step(dt);
    MPI_Barrier(MPI_COMM_WORLD);
    state.SetIterationTime(MPI_Wtime() - start);
  }
  state.counters["ranks"] = parallel::worldSize();
  state.counters["cells_per_rank"] = static_cast<double>(global.cellCount()) / parallel::worldSize();
  state.counters["cells"] = static_cast<double>(global.cellCount());
  // Rank 0's ghost traffic per step (the communication-volume model of docs/parallel.md).
  state.counters["ghost_MB_per_step"] =
      static_cast<double>(split.receivedGhostBytes() - bytesBefore) / 1e6 / static_cast<double>(state.iterations());
}
// Strong scaling: one n^3 grid, whatever the rank count.
void BM_SplitSmokeStep(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  runSplitSmoke(state, GridSpec<3>(Vec<3>::Zero(), 1.0 / n, IVec<3>::Constant(n)), static_cast<int>(state.range(1)));
}
BENCHMARK(BM_SplitSmokeStep)
    ->ArgsProduct({{64, 128, 256}, {1, 2}})
    ->ArgNames({"n", "threads"})
    ->UseManualTime()
    ->Iterations(3)
    ->Unit(benchmark::kMillisecond);

// Weak scaling: n^3 cells per rank, the grid growing along z with the rank count.
void BM_SplitSmokeStepWeak(benchmark::State& state) {
  const int n = static_cast<int>(state.range(0));
  runSplitSmoke(state, GridSpec<3>(Vec<3>::Zero(), 1.0 / n, IVec<3>(n, n, n * parallel::worldSize())), 1);
}
BENCHMARK(BM_SplitSmokeStepWeak)->Arg(128)->ArgName("n")->UseManualTime()->Iterations(3)->Unit(benchmark::kMillisecond);

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
