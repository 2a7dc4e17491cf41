// MPRGP on a 256^2 unilateral-pressure LCP (Narain eqs. 4.15-4.19): A = 5-point Laplacian with
// p = 0 outside the box, b = a random divergence in [-1, 1], relative projected gradient 1e-6.
// Cases: matrix-free stencil and assembled sparse matrix, both cold (p = 0), and a warm start
// from the previous solution with b perturbed by 1% (as between time steps); the same Laplacian as
// a GridPoissonQpOperator, cold, with Jacobi and with MIC(0)-in-face preconditioning.
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

// Matrix-free 5-point Laplacian (unit spacing) with homogeneous Dirichlet boundaries.
class Laplacian2d final : public QpOperator {
 public:
  explicit Laplacian2d(int n) : n_(n) {}
  Eigen::Index size() const override { return Eigen::Index{n_} * n_; }
  void apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const override {
    for (int j = 0; j < n_; ++j)
      for (int i = 0; i < n_; ++i) {
        const Eigen::Index k = Eigen::Index{j} * n_ + i;
        double s = 4.0 * x[k];
        if (i > 0) s -= x[k - 1];
        if (i + 1 < n_) s -= x[k + 1];
        if (j > 0) s -= x[k - n_];
        if (j + 1 < n_) s -= x[k + n_];
        y[k] = s;
      }
  }
  void diagonal(Eigen::VectorXd& d) const override { d = Eigen::VectorXd::Constant(size(), 4.0); }
  double normUpperBound() const override { return 8.0; }

 private:
  int n_;
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

void BM_ColdSolve(benchmark::State& state, bool matrixFree) {
  const Eigen::SparseMatrix<double> matrix = assemble(kRes);
  const Laplacian2d stencil(kRes);
  const SparseQpOperator sparse(matrix);
  const QpOperator& A = matrixFree ? static_cast<const QpOperator&>(stencil) : sparse;
  Rng rng(1);
  const Eigen::VectorXd b = randomDivergence(A.size(), rng);
  BoundQpSettings settings;
  settings.tolerance = 1e-6;
  BoundQpSolver solver;
  Eigen::VectorXd p(A.size());
  BoundQpResult r;
  for (auto _ : state) {
    p.setZero();
    r = solver.solve(A, b, p, settings);
    benchmark::DoNotOptimize(p.data());
  }
  report(state, r, A.size());
}

// Unit face weights (the boundary faces included), so A is the Laplacian of Laplacian2d.
void BM_ColdSolveGrid(benchmark::State& state, bool mic0) {
  const std::size_t n = std::size_t{kRes} * kRes;
  const IVec<2> res(kRes, kRes);
  const std::array<std::vector<double>, 2> lower{std::vector<double>(n, 1.0), std::vector<double>(n, 1.0)};
  const std::vector<double> diagonal(n, 4.0);
  const GridPoissonQpOperator<2> A(res, lower, diagonal);
  GridMic0FacePreconditioner<2> preconditioner(res, lower, diagonal);
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
    const int before = preconditioner.factorizations();
    r = solver.solve(A, b, p, settings, mic0 ? &preconditioner : nullptr);
    factorizations = preconditioner.factorizations() - before;
    benchmark::DoNotOptimize(p.data());
  }
  report(state, r, A.size());
  if (mic0) state.counters["factorizations"] = factorizations;
}

void BM_WarmSolve(benchmark::State& state) {
  const Laplacian2d A(kRes);
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

BENCHMARK_CAPTURE(BM_ColdSolve, matrix_free_256, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ColdSolve, sparse_256, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ColdSolveGrid, grid_jacobi_256, false)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK_CAPTURE(BM_ColdSolveGrid, grid_mic0_256, true)->Unit(benchmark::kMillisecond)->UseRealTime();
BENCHMARK(BM_WarmSolve)->Name("BM_WarmSolve/matrix_free_256_b_drift_1pct")->Unit(benchmark::kMillisecond)->UseRealTime();
