// 128^3 closed-box pressure projection from a random-divergence velocity to relative residual
// 1e-3, with the multigrid- and the MIC(0)-preconditioned CG. Counters: CG iterations, and the
// resident memory the projection object and its solver hold, per cell.
#include <benchmark/benchmark.h>

#include <fstream>
#include <string>

#include "msim/core/rng.hpp"
#include "msim/numerics/pressure/projection.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr int kRes = 128;
const IVec3 kSmokeRes(128, 192, 128);  // the grid of the 3D smoke step target

// Resident set size from /proc/self/statm [bytes].
double residentBytes() {
  std::ifstream statm("/proc/self/statm");
  double pages = 0.0, resident = 0.0;
  statm >> pages >> resident;
  return resident * 4096.0;
}

void BM_Projection(benchmark::State& state, PressurePreconditioner preconditioner, IVec3 res) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / kRes, res);
  MacGrid<3> start(spec);
  Rng rng(1);
  for (int a = 0; a < 3; ++a)
    for (float& v : start.component(a).data()) v = static_cast<float>(rng.uniform(-1.0, 1.0));
  ProjectionSettings settings;
  settings.preconditioner = preconditioner;
  settings.pcg.tolerance = 1e-3;
  settings.pcg.maxIterations = 1000;

  const double before = residentBytes();
  PressureProjection<3> proj(spec, DomainSides<3>::allWalls(), settings);
  MacGrid<3> u = start;
  PcgStats stats = proj.project(u, 0.01, 1.0);  // touches every work vector once
  const double bytesPerCell = (residentBytes() - before) / static_cast<double>(spec.cellCount());

  for (auto _ : state) {
    state.PauseTiming();
    u = start;
    proj.pressure().fill(0.0f);  // a cold solve every time: no warm start
    state.ResumeTiming();
    stats = proj.project(u, 0.01, 1.0);
    benchmark::DoNotOptimize(u.component(0).data().data());
  }
  state.counters["iterations"] = stats.iterations;
  state.counters["rel_residual"] = stats.relativeResidual;
  state.counters["bytes/cell"] = bytesPerCell;
  state.counters["levels"] = proj.multigridLevels();
}

}  // namespace

BENCHMARK_CAPTURE(BM_Projection, multigrid_pcg_128, PressurePreconditioner::Multigrid, IVec3::Constant(kRes))->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_Projection, mic0_pcg_128, PressurePreconditioner::Mic0, IVec3::Constant(kRes))->Unit(benchmark::kMillisecond)->UseRealTime()->Iterations(2);
BENCHMARK_CAPTURE(BM_Projection, multigrid_pcg_128x192x128, PressurePreconditioner::Multigrid, kSmokeRes)->Unit(benchmark::kMillisecond)->UseRealTime();
