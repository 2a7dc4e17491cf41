// MPRGP on a 256^2 unilateral-pressure LCP (Narain eqs. 4.15-4.19): A = 5-point Laplacian with
// p = 0 outside the box, b = a random divergence in [-1, 1], relative projected gradient 1e-6.
// Cases, cold (p = 0): the matrix-free GridPoissonQpOperator with Jacobi and with MIC(0)-in-face
// preconditioning, and the same matrix assembled (SparseQpOperator) with Jacobi; warm: from the
// previous solution with b perturbed by 1% (as between time steps).
// Counters: iterations, CG/expansion/proportioning steps, active fraction at the solution, and
// MIC(0) factorisations (one per distinct face).
#include <benchmark/benchmark.h>

#include <Eigen/SparseCore>
#include <array>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr int kRes = 256;

// The stencil data of the Laplacian: unit face weights (the boundary faces included, so p = 0
// outside the box) and diagonal 4.
struct UnitLaplacian {
  IVec<2> res = IVec<2>(kRes, kRes);
  std::array<std::vector<double>, 2> lower{std::vector<double>(std::size_t{kRes} * kRes, 1.0),
                                           std::vector<double>(std::size_t{kRes} * kRes, 1.0)};
  std::vector<double> diagonal = std::vector<double>(std::size_t{kRes} * kRes, 4.0);
};

Eigen::SparseMatrix<double> assemble(int n) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int k = j * n + i;
      t.emplace_back(k, k, 4.0);
      if (i > 0) t.emplace_back(k, k - 1, -1.0);
      if (i + 1 < n) t.emplace_back(k, k + 1, -1.0);
      if (j > 0) t.emplace_back(k, k - n, -1.0);
      if (j + 1 < n) t.emplace_back(k, k + n, -1.0);
    }
  Eigen::SparseMatrix<double> A(n * n, n * n);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

Eigen::VectorXd randomDivergence(Eigen::Index size, Rng& rng) {
  Eigen::VectorXd b(size);
  for (double& v : b) v = rng.uniform(-1.0, 1.0);
  return b;
}

void report(benchmark::State& state, const BoundQpResult& r, Eigen::Index size) {
  state.counters["iterations"] = r.iterations;
  state.counters["cg"] = r.cgSteps;
  state.counters["expansion"] = r.expansionSteps;
  state.counters["proportioning"] = r.proportioningSteps;
  state.counters["active_frac"] = static_cast<double>(r.activeCount) / static_cast<double>(size);
  state.counters["rel_gP"] = r.relativeProjectedGradient;
}

// Cold solves of A p = b, p >= 0, from p = 0 every iteration.
void coldSolves(benchmark::State& state, const QpOperator& A, GridMic0FacePreconditioner<2>* mic0) {
  Rng rng(1);
  const Eigen::VectorXd b = randomDivergence(A.size(), rng);
  BoundQpSettings settings;
  settings.tolerance = 1e-6;
  BoundQpSolver solver;
  Eigen::VectorXd p(A.size());
  BoundQpResult r;
  int factorizations = 0;
  for (auto _ : state) {
    p.setZero();
    const int before = mic0 ? mic0->factorizations() : 0;
    r = solver.solve(A, b, p, settings, mic0);
    if (mic0) factorizations = mic0->factorizations() - before;
    benchmark::DoNotOptimize(p.data());
  }
  report(state, r, A.size());
  if (mic0) state.counters["factorizations"] = factorizations;
}

void BM_ColdSolveGrid(benchmark::State& state, bool useMic0) {
  const UnitLaplacian l;
  const GridPoissonQpOperator<2> A(l.res, l.lower, l.diagonal);
  GridMic0FacePreconditioner<2> mic0(l.res, l.lower, l.diagonal);
  coldSolves(state, A, useMic0 ? &mic0 : nullptr);
}

void BM_ColdSolveSparse(benchmark::State& state) {
  const Eigen::SparseMatrix<double> matrix = assemble(kRes);
  coldSolves(state, SparseQpOperator(matrix), nullptr);
}

void BM_WarmSolve(benchmark::State& state) {
  const UnitLaplacian l;
  const GridPoissonQpOperator<2> A(l.res, l.lower, l.diagonal);
  Rng rng(1);
  const Eigen::VectorXd b0 = randomDivergence(A.size(), rng);
  BoundQpSettings settings;
  settings.tolerance = 1e-6;
  BoundQpSolver solver;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(A.size());
  solver.solve(A, b0, p, settings);
  Eigen::VectorXd b = b0;
  BoundQpResult r;
  for (auto _ : state) {
    state.PauseTiming();
    for (double& v : b) v += 0.01 * rng.uniform(-1.0, 1.0);
    state.ResumeTiming();
    r = solver.solve(A, b, p, settings);
    benchmark::DoNotOptimize(p.data());
  }
  report(state, r, A.size());
}

}  // namespace

BENCHMARK(BM_ColdSolveSparse)->Name("BM_ColdSolve/sparse_256")->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ColdSolveGrid, grid_jacobi_256, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ColdSolveGrid, grid_mic0_256, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WarmSolve)->Name("BM_WarmSolve/grid_256_b_drift_1pct")->Unit(benchmark::kMillisecond)->UseRealTime();
