// MPRGP with box constraints lower <= p <= upper (the form of Narain's friction bounds
// -s_max <= s_ij <= s_max, eq. 5.15): agreement with an exhaustive search over the 3^n
// lower / free / upper assignments on small dense problems, the box KKT conditions on random
// Poisson problems with two-sided bounds (Jacobi and MIC(0) in face), bounds that exclude 0 with
// b = 0, and equal bounds (fixed entries).
#include <gtest/gtest.h>

#include <Eigen/Dense>
#include <array>
#include <cmath>
#include <cstdio>
#include <limits>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "random_spd.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

using SpMat = Eigen::SparseMatrix<double>;
constexpr double kInf = std::numeric_limits<double>::infinity();

double objective(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& p) {
  return 0.5 * p.dot(A * p) - b.dot(p);
}

// The minimiser by exhaustive search: every entry at its lower bound, its upper bound or free;
// solve for the free ones and keep the feasible assignment with the smallest objective (the
// problem is strictly convex, so that is the unique minimiser).
Eigen::VectorXd bruteForceBox(const Eigen::MatrixXd& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo,
                              const Eigen::VectorXd& hi) {
  const int n = static_cast<int>(b.size());
  int assignments = 1;
  for (int i = 0; i < n; ++i) assignments *= 3;
  Eigen::VectorXd best;
  double bestF = kInf;
  for (int code = 0; code < assignments; ++code) {
    std::vector<int> state(n), F;
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
    bool finiteBounds = true;  // an entry cannot sit at an infinite bound
    for (int i = 0, c = code; i < n; ++i, c /= 3) {
      state[i] = c % 3;
      if (state[i] == 0) p[i] = lo[i];
      if (state[i] == 2) p[i] = hi[i];
      if (state[i] == 1) F.push_back(i);
      finiteBounds = finiteBounds && std::isfinite(p[i]);
    }
    if (!finiteBounds) continue;
    if (!F.empty()) {
      const int m = static_cast<int>(F.size());
      Eigen::MatrixXd AFF(m, m);
      Eigen::VectorXd rhs(m);
      for (int r = 0; r < m; ++r) {
        rhs[r] = b[F[r]];
        for (int c = 0; c < n; ++c)
          if (state[c] != 1) rhs[r] -= A(F[r], c) * p[c];
        for (int c = 0; c < m; ++c) AFF(r, c) = A(F[r], F[c]);
      }
      const Eigen::VectorXd pF = AFF.ldlt().solve(rhs);
      for (int r = 0; r < m; ++r) p[F[r]] = pF[r];
    }
    bool feasible = true;
    for (int i = 0; i < n; ++i) feasible = feasible && p[i] >= lo[i] - 1e-12 && p[i] <= hi[i] + 1e-12;
    if (!feasible) continue;
    const double f = objective(A, b, p);
    if (f < bestF) {
      bestF = f;
      best = p;
    }
  }
  return best;
}

// Largest violation of the box KKT conditions: p in [lo, hi]; g = A p - b is >= 0 at a lower
// bound, <= 0 at an upper bound and 0 in between.
double boxKktError(const SpMat& A, const Eigen::VectorXd& b, const Eigen::VectorXd& lo, const Eigen::VectorXd& hi,
                   const Eigen::VectorXd& p) {
  const Eigen::VectorXd g = A * p - b;
  double e = 0.0;
  for (Eigen::Index i = 0; i < p.size(); ++i) {
    e = std::max({e, lo[i] - p[i], p[i] - hi[i]});
    if (p[i] <= lo[i] && p[i] < hi[i]) e = std::max(e, -g[i]);
    else if (p[i] >= hi[i] && p[i] > lo[i]) e = std::max(e, g[i]);
    else if (p[i] > lo[i] && p[i] < hi[i]) e = std::max(e, std::abs(g[i]));
  }
  return e;
}

}  // namespace

TEST(BoundQpBox, MatchesExhaustiveSearchOnSmallDenseProblems) {
  Rng rng(17);
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-13;
  double worst = 0.0;
  int bothBoundsHit = 0, total = 0;
  for (int n = 1; n <= 7; ++n)
    for (int trial = 0; trial < 20; ++trial) {
      const Eigen::MatrixXd dense = randomSpd(n, rng, 0.1);
      const SpMat A = dense.sparseView();
      Eigen::VectorXd b(n), lo(n), hi(n);
      for (int i = 0; i < n; ++i) {
        b[i] = rng.uniform(-2.0, 2.0);
        // Friction-like symmetric bounds, one-sided ones and an unbounded entry now and then.
        const double s = rng.uniform(0.05, 0.5);
        const int kind = static_cast<int>(rng.uniform(0.0, 4.0));
        lo[i] = kind == 1 ? 0.0 : (kind == 3 ? -kInf : -s);
        hi[i] = kind == 2 ? kInf : s;
      }
      const Eigen::VectorXd expected = bruteForceBox(dense, b, lo, hi);
      Eigen::VectorXd p(n);  // an arbitrary warm start, projected by the solver
      for (int i = 0; i < n; ++i) p[i] = rng.uniform(-1.0, 1.0);
      const BoundQpResult r = solver.solve(SparseQpOperator(A), b, lo, hi, p, settings);
      ASSERT_TRUE(r.converged) << "n=" << n << " trial=" << trial;
      const double err = (p - expected).lpNorm<Eigen::Infinity>();
      worst = std::max(worst, err);
      EXPECT_LE(err, 1e-8) << "n=" << n << " trial=" << trial;
      bool atLower = false, atUpper = false;
      for (int i = 0; i < n; ++i) {
        atLower = atLower || p[i] == lo[i];
        atUpper = atUpper || p[i] == hi[i];
      }
      bothBoundsHit += atLower && atUpper;
      ++total;
    }
  std::printf("[bound_qp box] exhaustive search: %d problems (%d with entries at both kinds of bound), max error %.2e\n",
              total, bothBoundsHit, worst);
  EXPECT_GT(bothBoundsHit, total / 4);
}

TEST(BoundQpBox, KktOnRandomPoissonProblemsWithTwoSidedBounds) {
  // -div(w grad) on 48 x 48 cells with unit-ish weights, b random in [-1, 1], bounds
  // -s_max <= p <= s_max with s_max varying per cell (as alpha p varies in eq. 5.15).
  Rng rng(23);
  const IVec2 res(48, 48);
  const int n = res.x() * res.y();
  std::array<std::vector<double>, 2> lower{std::vector<double>(n), std::vector<double>(n)};
  std::vector<double> diag(n, 0.0);
  for (int j = 0; j < res.y(); ++j)
    for (int i = 0; i < res.x(); ++i) {
      const int k = j * res.x() + i;
      for (int a = 0; a < 2; ++a) {
        const double w = rng.uniform(0.5, 2.0);
        lower[a][k] = w;
        diag[k] += w;
        const int neighbour = a == 0 ? (i > 0 ? k - 1 : -1) : (j > 0 ? k - res.x() : -1);
        if (neighbour >= 0) diag[neighbour] += w;
      }
    }
  for (int k = 0; k < n; ++k) diag[k] += 0.05;  // a little mass term: strictly positive definite
  const GridPoissonQpOperator<2> A(res, lower, diag);
  Eigen::VectorXd b(n), lo(n), hi(n);
  for (int k = 0; k < n; ++k) {
    b[k] = rng.uniform(-1.0, 1.0);
    hi[k] = rng.uniform(0.0, 0.3);
    lo[k] = -hi[k];
  }
  // Assemble the same operator for the independent KKT check.
  SpMat M(n, n);
  {
    std::vector<Eigen::Triplet<double>> t;
    Eigen::VectorXd e = Eigen::VectorXd::Zero(n), col(n);
    for (int k = 0; k < n; ++k) {
      e[k] = 1.0;
      A.apply(e, col);
      for (int r = 0; r < n; ++r)
        if (col[r] != 0.0) t.emplace_back(r, k, col[r]);
      e[k] = 0.0;
    }
    M.setFromTriplets(t.begin(), t.end());
  }
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-10;
  for (const bool mic : {false, true}) {
    GridMic0FacePreconditioner<2> precond(res, lower, diag);
    Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
    const BoundQpResult r = solver.solve(A, b, lo, hi, p, settings, mic ? &precond : nullptr);
    ASSERT_TRUE(r.converged);
    const double err = boxKktError(M, b, lo, hi, p);
    int atBound = 0;
    for (int k = 0; k < n; ++k) atBound += p[k] == lo[k] || p[k] == hi[k];
    std::printf("[bound_qp box] 48x48 two-sided, %s: %d iterations, %d of %d entries at a bound, KKT error %.2e\n",
                mic ? "MIC(0)" : "Jacobi", r.iterations, atBound, n, err);
    EXPECT_LT(err, 1e-8);
    EXPECT_GT(atBound, n / 10);
    EXPECT_LT(atBound, n);
  }
}

TEST(BoundQpBox, BoundsThatExcludeZeroWithZeroRightHandSide) {
  // b = 0 and p >= 1: the minimiser of 1/2 p^T A p is no longer p = 0.
  const Eigen::MatrixXd dense = (Eigen::MatrixXd(3, 3) << 2, -1, 0, -1, 2, -1, 0, -1, 2).finished();
  const SpMat A = dense.sparseView();
  const Eigen::VectorXd b = Eigen::VectorXd::Zero(3), lo = Eigen::VectorXd::Ones(3),
                        hi = Eigen::VectorXd::Constant(3, kInf);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(3);
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-12;
  const BoundQpResult r = solver.solve(SparseQpOperator(A), b, lo, hi, p, settings);
  ASSERT_TRUE(r.converged);
  // g = A p at p = (1, 1, 1) is (1, 0, 1) >= 0: every entry at its bound is optimal.
  EXPECT_DOUBLE_EQ(p[0], 1.0);
  EXPECT_DOUBLE_EQ(p[1], 1.0);
  EXPECT_DOUBLE_EQ(p[2], 1.0);
  EXPECT_EQ(r.activeCount, 3);
}

TEST(BoundQpBox, EqualBoundsFixTheEntryAndNonNegativeBoundsMatchTheDefault) {
  Rng rng(5);
  const int n = 8;
  const Eigen::MatrixXd dense = randomSpd(n, rng, 0.2);
  const SpMat A = dense.sparseView();
  Eigen::VectorXd b(n);
  for (int i = 0; i < n; ++i) b[i] = rng.uniform(-1.0, 1.0);
  BoundQpSolver solver;
  BoundQpSettings settings;
  settings.tolerance = 1e-13;
  // [0, inf) as explicit bounds gives the p >= 0 solve's answer.
  Eigen::VectorXd p1 = Eigen::VectorXd::Zero(n), p2 = Eigen::VectorXd::Zero(n);
  solver.solve(SparseQpOperator(A), b, p1, settings);
  solver.solve(SparseQpOperator(A), b, Eigen::VectorXd::Zero(n), Eigen::VectorXd::Constant(n, kInf), p2, settings);
  EXPECT_LE((p1 - p2).lpNorm<Eigen::Infinity>(), 1e-10);
  // lo = hi = 0.3 on entry 2 pins it there; the rest match the brute force with that bound.
  Eigen::VectorXd lo = Eigen::VectorXd::Constant(n, -1.0), hi = Eigen::VectorXd::Constant(n, 1.0);
  lo[2] = hi[2] = 0.3;
  Eigen::VectorXd p = Eigen::VectorXd::Zero(n);
  ASSERT_TRUE(solver.solve(SparseQpOperator(A), b, lo, hi, p, settings).converged);
  EXPECT_EQ(p[2], 0.3);
  EXPECT_LE((p - bruteForceBox(dense, b, lo, hi)).lpNorm<Eigen::Infinity>(), 1e-8);
}

TEST(BoundQpBox, RejectsBadBounds) {
  const SpMat A = Eigen::MatrixXd::Identity(2, 2).sparseView();
  const Eigen::VectorXd b = Eigen::VectorXd::Ones(2);
  Eigen::VectorXd p = Eigen::VectorXd::Zero(2);
  BoundQpSolver solver;
  EXPECT_THROW(solver.solve(SparseQpOperator(A), b, Eigen::VectorXd::Zero(3), Eigen::VectorXd::Ones(2), p),
               std::invalid_argument);
  EXPECT_THROW(solver.solve(SparseQpOperator(A), b, Eigen::VectorXd::Ones(2), Eigen::VectorXd::Zero(2), p),
               std::invalid_argument);
  Eigen::VectorXd nanBound = Eigen::VectorXd::Zero(2);
  nanBound[1] = std::nan("");
  EXPECT_THROW(solver.solve(SparseQpOperator(A), b, nanBound, Eigen::VectorXd::Ones(2), p), std::invalid_argument);
}
