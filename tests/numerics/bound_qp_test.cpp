// MPRGP bound-constrained QP: KKT conditions on random Poisson-like LCPs, agreement with an
// exhaustive active-set search on small dense problems, the unconstrained limit against CG, and
// warm starts.
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <Eigen/IterativeLinearSolvers>
#include <Eigen/SparseCholesky>
#include <cstdio>
#include <optional>
#include <stdexcept>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "random_spd.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

using SpMat = Eigen::SparseMatrix<double>;

// -div(w grad) on an nx x ny cell grid with p = 0 outside (Dirichlet), face weights w in
// [wMin, wMax]: the structure of Narain eq. 4.18 with a varying density rho on the faces.
SpMat poisson2d(int nx, int ny, Rng& rng, double wMin, double wMax) {
  std::vector<Eigen::Triplet<double>> t;
  Eigen::VectorXd diag = Eigen::VectorXd::Zero(nx * ny);
  auto id = [nx](int i, int j) { return j * nx + i; };
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      // The faces to the right and above each cell; boundary faces couple to the ghost p = 0.
      for (int axis = 0; axis < 2; ++axis) {
        const double w = rng.uniform(wMin, wMax);
        const int ni = axis == 0 ? i + 1 : i, nj = axis == 0 ? j : j + 1;
        diag[id(i, j)] += w;
        if (ni < nx && nj < ny) {
          diag[id(ni, nj)] += w;
          t.emplace_back(id(i, j), id(ni, nj), -w);
          t.emplace_back(id(ni, nj), id(i, j), -w);
        }
      }
      if (i == 0) diag[id(i, j)] += rng.uniform(wMin, wMax);
      if (j == 0) diag[id(i, j)] += rng.uniform(wMin, wMax);
    }
  for (int k = 0; k < nx * ny; ++k) t.emplace_back(k, k, diag[k]);
  SpMat A(nx * ny, nx * ny);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

// The unique KKT point by exhaustive search over the 2^n free sets: solve A_FF p_F = b_F and keep
// the one with p_F >= 0 and (A p - b)_i >= 0 off F.
Eigen::VectorXd bruteForce(const Eigen::MatrixXd& A, const Eigen::VectorXd& b) {
  const int n = static_cast<int>(b.size());
  for (unsigned mask = 0; mask < (1u << n); ++mask) {
    std::vector<int> F;
    for (int i = 0; i < n; ++i)
      if (mask & (1u << i)) F.push_back(i);
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
    if (!F.empty()) {
      const int m = static_cast<int>(F.size());
      Eigen::MatrixXd AFF(m, m);
      Eigen::VectorXd bF(m);
      for (int r = 0; r < m; ++r) {
        bF[r] = b[F[r]];
        for (int c = 0; c < m; ++c) AFF(r, c) = A(F[r], F[c]);
      }
      const Eigen::VectorXd pF = AFF.ldlt().solve(bF);
      for (int r = 0; r < m; ++r) p[F[r]] = pF[r];
    }
    const Eigen::VectorXd g = A * p - b;
    bool ok = true;
    for (int i = 0; i < n; ++i) ok = ok && ((mask & (1u << i)) ? p[i] >= -1e-14 : g[i] >= -1e-14);
    if (ok) return p;
  }
  ADD_FAILURE() << "no KKT point found";
  return Eigen::VectorXd::Zero(n);
}

struct KktError {
  double negativeP = 0.0;       // max(-p_i)
  double activeGradient = 0.0;  // max(-g_i) where p_i = 0
  double freeGradient = 0.0;    // max |g_i| where p_i > 0
  double complementarity = 0.0;  // max |p_i g_i|
};

KktError kkt(const SpMat& A, const Eigen::VectorXd& b, const Eigen::VectorXd& p) {
  const Eigen::VectorXd g = A * p - b;
  KktError e;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    e.negativeP = std::max(e.negativeP, -p[i]);
    if (p[i] > 0.0)
      e.freeGradient = std::max(e.freeGradient, std::abs(g[i]));
    else
      e.activeGradient = std::max(e.activeGradient, -g[i]);
    e.complementarity = std::max(e.complementarity, std::abs(p[i] * g[i]));
  }
  return e;
}

TEST(BoundQp, MatchesExhaustiveActiveSetSearchOnSmallDenseProblems) {
  Rng rng(7);
  int mixed = 0, total = 0;
  double worst = 0.0;
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-13;
  for (int n = 1; n <= 10; ++n)
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::MatrixXd dense = randomSpd(n, rng, 0.1);
      const SpMat A = dense.sparseView();
      const Eigen::VectorXd b = randomVector(n, rng, -1.0, 1.0);
      const Eigen::VectorXd expected = bruteForce(dense, b);
      Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
      const BoundQpResult r = solver.solve(SparseQpOperator(A), b, p, settings);
      ASSERT_TRUE(r.converged) << "n=" << n << " trial=" << trial;
      const double err = (p - expected).lpNorm<Eigen::Infinity>() / std::max(1.0, expected.lpNorm<Eigen::Infinity>());
      worst = std::max(worst, err);
      EXPECT_LE(err, 1e-8) << "n=" << n << " trial=" << trial;
      ++total;
      if (r.activeCount > 0 && r.activeCount < n) ++mixed;
    }
  std::printf("[bound_qp] exhaustive search: %d problems (%d with mixed active sets), max error %.2e\n", total,
              mixed, worst);
  EXPECT_GT(mixed, total / 2);  // the comparison exercises non-trivial active sets
}

TEST(BoundQp, KktConditionsOnRandomPoissonLcps) {
  Rng rng(11);
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-10;
  const int sizes[][2] = {{10, 10}, {20, 20}, {32, 32}, {44, 45}};
  for (const auto& s : sizes)
    for (const bool varying : {false, true})
      for (const auto pre : {BoundQpPreconditioning::Jacobi, BoundQpPreconditioning::None}) {
        const SpMat A = poisson2d(s[0], s[1], rng, varying ? 0.1 : 1.0, varying ? 10.0 : 1.0);
        const Eigen::VectorXd b = randomVector(A.rows(), rng, -1.0, 1.0);
        Eigen::VectorXd p = Eigen::VectorXd::Zero(A.rows());
        settings.preconditioning = pre;
        const BoundQpResult r = solver.solve(SparseQpOperator(A), b, p, settings);
        ASSERT_TRUE(r.converged);
        const double tol = settings.tolerance * b.norm();
        const KktError e = kkt(A, b, p);
        EXPECT_EQ(e.negativeP, 0.0);
        EXPECT_LE(e.activeGradient, tol);
        EXPECT_LE(e.freeGradient, tol);
        EXPECT_LE(e.complementarity, tol * p.lpNorm<Eigen::Infinity>());
        EXPECT_GT(r.activeCount, 0);
        EXPECT_LT(r.activeCount, A.rows());
        EXPECT_EQ(r.iterations, r.cgSteps + r.expansionSteps + r.proportioningSteps);
        std::printf("[bound_qp] %dx%d %s %s: %d it (cg %d, exp %d, prop %d), %d A-products, active %d/%ld, "
                    "|g^P|/|b| %.1e\n",
                    s[0], s[1], varying ? "w in [0.1,10]" : "w = 1", pre == BoundQpPreconditioning::Jacobi ? "jacobi" : "none",
                    r.iterations, r.cgSteps, r.expansionSteps, r.proportioningSteps, r.operatorApplications,
                    r.activeCount, static_cast<long>(A.rows()), r.relativeProjectedGradient);
      }
}

TEST(BoundQp, UnconstrainedSolutionEqualsConjugateGradients) {
  Rng rng(3);
  const SpMat A = poisson2d(30, 30, rng, 0.1, 10.0);
  const Eigen::VectorXd exact = randomVector(A.rows(), rng, 1.0, 2.0);
  const Eigen::VectorXd b = A * exact;

  Eigen::ConjugateGradient<SpMat, Eigen::Lower | Eigen::Upper, Eigen::DiagonalPreconditioner<double>> cg(A);
  cg.setTolerance(1e-12);
  const Eigen::VectorXd cgSolution = cg.solve(b);

  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-12;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(A.rows());
  const BoundQpResult cold = solver.solve(SparseQpOperator(A), b, p, settings);
  ASSERT_TRUE(cold.converged);
  EXPECT_EQ(cold.activeCount, 0);
  EXPECT_LE((p - cgSolution).lpNorm<Eigen::Infinity>(), 1e-8);

  // From a positive start whose CG path stays positive, MPRGP is Jacobi-PCG step for step.
  Eigen::VectorXd warm = Eigen::VectorXd::Constant(A.rows(), 1.5);
  const BoundQpResult fromInterior = solver.solve(SparseQpOperator(A), b, warm, settings);
  ASSERT_TRUE(fromInterior.converged);
  EXPECT_LE((warm - cgSolution).lpNorm<Eigen::Infinity>(), 1e-8);
  const long cgColdIterations = static_cast<long>(cg.iterations());
  const Eigen::VectorXd cgWarm = cg.solveWithGuess(b, Eigen::VectorXd::Constant(A.rows(), 1.5));
  EXPECT_LE((warm - cgWarm).lpNorm<Eigen::Infinity>(), 1e-8);
  std::printf("[bound_qp] unconstrained 30x30: MPRGP from 0: %d it (cg %d, exp %d, prop %d); from 1.5: %d it "
              "(cg %d, exp %d, prop %d); Eigen Jacobi-PCG from 0: %ld it, from 1.5: %ld it; |p - p_cg| %.1e\n",
              cold.iterations, cold.cgSteps, cold.expansionSteps, cold.proportioningSteps, fromInterior.iterations,
              fromInterior.cgSteps, fromInterior.expansionSteps, fromInterior.proportioningSteps, cgColdIterations,
              static_cast<long>(cg.iterations()), (p - cgSolution).lpNorm<Eigen::Infinity>());
}

TEST(BoundQp, WarmStartFromTheSolutionNeedsAtMostOneIteration) {
  Rng rng(5);
  const SpMat A = poisson2d(40, 40, rng, 0.1, 10.0);
  const Eigen::VectorXd b = randomVector(A.rows(), rng, -1.0, 1.0);
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-10;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(A.rows());
  const BoundQpResult cold = solver.solve(SparseQpOperator(A), b, p, settings);
  ASSERT_TRUE(cold.converged);
  const BoundQpResult warm = solver.solve(SparseQpOperator(A), b, p, settings);
  EXPECT_TRUE(warm.converged);
  EXPECT_LE(warm.iterations, 1);

  // A slightly changed right-hand side, as between time steps: the warm start pays off.
  const Eigen::VectorXd b2 = b + 0.01 * randomVector(A.rows(), rng, -1.0, 1.0);
  Eigen::VectorXd pWarm = p, pCold = Eigen::VectorXd::Zero(A.rows());
  const BoundQpResult perturbedWarm = solver.solve(SparseQpOperator(A), b2, pWarm, settings);
  const BoundQpResult perturbedCold = solver.solve(SparseQpOperator(A), b2, pCold, settings);
  ASSERT_TRUE(perturbedWarm.converged && perturbedCold.converged);
  EXPECT_LT(perturbedWarm.iterations, perturbedCold.iterations);
  EXPECT_LE((pWarm - pCold).lpNorm<Eigen::Infinity>(), 1e-7 * pCold.lpNorm<Eigen::Infinity>());
  std::printf("[bound_qp] 40x40: cold %d it, warm from solution %d it; b perturbed by 1%%: warm %d it, cold %d it\n",
              cold.iterations, warm.iterations, perturbedWarm.iterations, perturbedCold.iterations);
}

// Jacobi through the preconditioner hook: must reproduce the built-in Jacobi exactly and be told
// about every face before it is applied.
class HookJacobi final : public QpFacePreconditioner {
 public:
  explicit HookJacobi(const Eigen::VectorXd& diagonal) : inverseDiagonal_(diagonal.cwiseInverse()) {}
  void setFace(const std::vector<std::uint8_t>& free) override {
    free_ = &free;
    ++faces;
  }
  void apply(const Eigen::VectorXd& g, Eigen::VectorXd& z) override {
    for (Eigen::Index i = 0; i < g.size(); ++i) z[i] = (*free_)[i] ? g[i] * inverseDiagonal_[i] : 0.0;
  }
  int faces = 0;

 private:
  Eigen::VectorXd inverseDiagonal_;
  const std::vector<std::uint8_t>* free_ = nullptr;
};

TEST(BoundQp, PreconditionerHookReproducesBuiltInJacobi) {
  Rng rng(9);
  const SpMat A = poisson2d(25, 25, rng, 0.1, 10.0);
  const Eigen::VectorXd b = randomVector(A.rows(), rng, -1.0, 1.0);
  BoundQpSolver solver;
  Eigen::VectorXd p1 = Eigen::VectorXd::Zero(A.rows()), p2 = p1;
  const BoundQpResult builtIn = solver.solve(SparseQpOperator(A), b, p1);
  HookJacobi hook(A.diagonal());
  const BoundQpResult hooked = solver.solve(SparseQpOperator(A), b, p2, {}, &hook);
  EXPECT_EQ(builtIn.iterations, hooked.iterations);
  EXPECT_EQ(hooked.expansionSteps + hooked.proportioningSteps + 1, hook.faces);
  EXPECT_LE((p1 - p2).lpNorm<Eigen::Infinity>(), 1e-14 * p1.lpNorm<Eigen::Infinity>());
}

TEST(BoundQp, ZeroRightHandSideGivesZero) {
  Rng rng(1);
  const SpMat A = poisson2d(5, 5, rng, 1.0, 1.0);
  Eigen::VectorXd p = Eigen::VectorXd::Constant(25, 3.0);
  const BoundQpResult r = BoundQpSolver().solve(SparseQpOperator(A), Eigen::VectorXd::Zero(25), p);
  EXPECT_TRUE(r.converged);
  EXPECT_EQ(p, Eigen::VectorXd::Zero(25));
}

TEST(BoundQp, RejectsMismatchedSizesAndBadSettings) {
  Rng rng(1);
  const SpMat A = poisson2d(4, 4, rng, 1.0, 1.0);
  const SparseQpOperator op(A);
  BoundQpSolver solver;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(16), shortP = Eigen::VectorXd::Zero(15);
  EXPECT_THROW(solver.solve(op, Eigen::VectorXd::Ones(15), p), std::invalid_argument);
  EXPECT_THROW(solver.solve(op, Eigen::VectorXd::Ones(16), shortP), std::invalid_argument);
  BoundQpSettings bad;
  bad.alphaBarFactor = 2.5;
  EXPECT_THROW(solver.solve(op, Eigen::VectorXd::Ones(16), p, bad), std::invalid_argument);
  const SpMat rectangular(3, 4);
  EXPECT_THROW(SparseQpOperator{rectangular}, std::invalid_argument);
}

}  // namespace
