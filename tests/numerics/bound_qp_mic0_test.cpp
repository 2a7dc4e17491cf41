// MIC(0)-in-face preconditioning of MPRGP on a 64^2 face-weighted Poisson grid (weights in
// [0.1, 10], Dirichlet boundary): the grid operator against the assembled matrix, the same
// solutions as Jacobi MPRGP in fewer iterations (unconstrained and constrained), and symmetry and
// positivity of M_FF^{-1} on random faces.
#include <gtest/gtest.h>

#include <Eigen/SparseCore>
#include <array>
#include <cmath>
#include <cstdint>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/bound_qp.hpp"
#include "msim/numerics/bound_qp_mic0.hpp"
#include "random_spd.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr int kN = 64;

// Stencil data of -div(w grad) on kN x kN cells, every face (boundary faces included, coupling to
// a ghost p = 0) with a weight uniform in [0.1, 10].
struct Stencil {
  IVec<2> res{kN, kN};
  std::array<std::vector<double>, 2> lower;
  std::vector<double> diag;
};

Stencil randomStencil(Rng& rng) {
  Stencil s;
  const std::size_t n = std::size_t{kN} * kN;
  for (auto& w : s.lower) w.resize(n);
  s.diag.assign(n, 0.0);
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const std::size_t k = std::size_t(j) * kN + i;
      for (int a = 0; a < 2; ++a) {
        const double w = rng.uniform(0.1, 10.0);
        s.lower[a][k] = w;
        s.diag[k] += w;
        const bool hasLower = a == 0 ? i > 0 : j > 0;
        if (hasLower) s.diag[k - (a == 0 ? 1 : kN)] += w;
      }
      if (i + 1 == kN) s.diag[k] += rng.uniform(0.1, 10.0);  // upper domain faces
      if (j + 1 == kN) s.diag[k] += rng.uniform(0.1, 10.0);
    }
  return s;
}

Eigen::SparseMatrix<double> assemble(const Stencil& s) {
  std::vector<Eigen::Triplet<double>> t;
  for (int j = 0; j < kN; ++j)
    for (int i = 0; i < kN; ++i) {
      const int k = j * kN + i;
      t.emplace_back(k, k, s.diag[k]);
      if (i > 0) {
        t.emplace_back(k, k - 1, -s.lower[0][k]);
        t.emplace_back(k - 1, k, -s.lower[0][k]);
      }
      if (j > 0) {
        t.emplace_back(k, k - kN, -s.lower[1][k]);
        t.emplace_back(k - kN, k, -s.lower[1][k]);
      }
    }
  Eigen::SparseMatrix<double> A(kN * kN, kN * kN);
  A.setFromTriplets(t.begin(), t.end());
  return A;
}

void print(const char* name, const BoundQpResult& r) {
  std::printf("  %-7s %4d iterations (CG %d, expansion %d, proportioning %d), rel gP %.2e\n", name, r.iterations,
              r.cgSteps, r.expansionSteps, r.proportioningSteps, r.relativeProjectedGradient);
}

TEST(BoundQpMic0, GridOperatorMatchesAssembledMatrix) {
  Rng rng(11);
  const Stencil s = randomStencil(rng);
  const Eigen::SparseMatrix<double> matrix = assemble(s);
  const GridPoissonQpOperator<2> A(s.res, s.lower, s.diag);
  const SparseQpOperator reference(matrix);
  ASSERT_EQ(A.size(), matrix.rows());
  const Eigen::VectorXd x = randomVector(A.size(), rng, -1.0, 1.0);
  Eigen::VectorXd y(A.size()), yRef(A.size());
  A.apply(x, y);
  reference.apply(x, yRef);
  EXPECT_LT((y - yRef).lpNorm<Eigen::Infinity>(), 1e-12);
  Eigen::VectorXd d;
  A.diagonal(d);
  EXPECT_EQ(d, matrix.diagonal());
  EXPECT_DOUBLE_EQ(A.normUpperBound(), reference.normUpperBound());
  EXPECT_THROW(GridPoissonQpOperator<2>(IVec<2>(kN, kN + 1), s.lower, s.diag), std::invalid_argument);
  EXPECT_THROW(GridMic0FacePreconditioner<2>(s.res, s.lower, std::vector<double>(s.diag.size(), 0.0)),
               std::invalid_argument);
}

TEST(BoundQpMic0, UnconstrainedSameSolutionAsJacobiInFewerIterations) {
  Rng rng(12);
  const Stencil s = randomStencil(rng);
  const GridPoissonQpOperator<2> A(s.res, s.lower, s.diag);
  GridMic0FacePreconditioner<2> mic0(s.res, s.lower, s.diag);
  const Eigen::VectorXd pStar = randomVector(A.size(), rng, 1.0, 2.0);
  Eigen::VectorXd b(A.size());
  A.apply(pStar, b);
  BoundQpSettings settings;
  settings.tolerance = 1e-12;
  BoundQpSolver solver;
  // From p = 1.5 everywhere the face is all free and stays so: pure preconditioned CG.
  Eigen::VectorXd pJacobi = Eigen::VectorXd::Constant(A.size(), 1.5), pMic0 = pJacobi;
  const BoundQpResult jacobi = solver.solve(A, b, pJacobi, settings);
  const BoundQpResult mic = solver.solve(A, b, pMic0, settings, &mic0);
  std::printf("unconstrained 64^2, w in [0.1, 10], tolerance 1e-12:\n");
  print("Jacobi", jacobi);
  print("MIC(0)", mic);
  ASSERT_TRUE(jacobi.converged);
  ASSERT_TRUE(mic.converged);
  EXPECT_LT((pMic0 - pJacobi).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT((pMic0 - pStar).lpNorm<Eigen::Infinity>(), 1e-8);
  EXPECT_LT(mic.iterations, jacobi.iterations / 2);
  EXPECT_EQ(mic0.factorizations(), 1);  // the all-free face of the constructor is reused
}

TEST(BoundQpMic0, ConstrainedSameSolutionAsJacobiAndKkt) {
  Rng rng(13);
  const Stencil s = randomStencil(rng);
  const GridPoissonQpOperator<2> A(s.res, s.lower, s.diag);
  GridMic0FacePreconditioner<2> mic0(s.res, s.lower, s.diag);
  const Eigen::VectorXd b = randomVector(A.size(), rng, -1.0, 1.0);
  BoundQpSettings settings;
  settings.tolerance = 1e-11;
  BoundQpSolver solver;
  Eigen::VectorXd pJacobi = Eigen::VectorXd::Zero(A.size()), pMic0 = pJacobi;
  const BoundQpResult jacobi = solver.solve(A, b, pJacobi, settings);
  const BoundQpResult mic = solver.solve(A, b, pMic0, settings, &mic0);
  std::printf("LCP 64^2, b in [-1, 1], tolerance 1e-11 (%d of %d active):\n", mic.activeCount,
              static_cast<int>(A.size()));
  print("Jacobi", jacobi);
  print("MIC(0)", mic);
  std::printf("  MIC(0) factorisations: %d\n", mic0.factorizations());
  ASSERT_TRUE(jacobi.converged);
  ASSERT_TRUE(mic.converged);
  EXPECT_GT(mic.activeCount, 0);
  EXPECT_LT(mic.activeCount, A.size());
  EXPECT_LT((pMic0 - pJacobi).lpNorm<Eigen::Infinity>(), 1e-7);
  EXPECT_LT(mic.iterations, jacobi.iterations);
  // KKT: p >= 0, g = A p - b >= 0 where p = 0, g = 0 where p > 0.
  Eigen::VectorXd g(A.size());
  A.apply(pMic0, g);
  g -= b;
  const double tol = 1e-9 * b.norm();
  for (Eigen::Index i = 0; i < A.size(); ++i) {
    ASSERT_GE(pMic0[i], 0.0);
    if (pMic0[i] > 0.0) {
      ASSERT_LT(std::abs(g[i]), tol) << i;
    } else {
      ASSERT_GT(g[i], -tol) << i;
    }
  }
}

TEST(BoundQpMic0, SymmetricPositiveDefiniteOnTheFace) {
  Rng rng(14);
  const Stencil s = randomStencil(rng);
  GridMic0FacePreconditioner<2> mic0(s.res, s.lower, s.diag);
  const Eigen::Index n = static_cast<Eigen::Index>(s.diag.size());
  std::vector<std::uint8_t> free(static_cast<std::size_t>(n));
  Eigen::VectorXd zx(n), zy(n);
  for (double freeFraction : {1.0, 0.7, 0.3}) {
    for (auto& f : free) f = rng.uniform() < freeFraction ? 1 : 0;
    const int before = mic0.factorizations();
    mic0.setFace(free);
    mic0.setFace(free);  // unchanged mask: no refactorisation
    EXPECT_EQ(mic0.factorizations(), before + (freeFraction < 1.0 ? 1 : 0));
    for (int trial = 0; trial < 5; ++trial) {
      const Eigen::VectorXd x = randomVector(n, rng, -1.0, 1.0), y = randomVector(n, rng, -1.0, 1.0);
      mic0.apply(x, zx);
      mic0.apply(y, zy);
      for (Eigen::Index i = 0; i < n; ++i)
        if (!free[static_cast<std::size_t>(i)]) {
          ASSERT_EQ(zx[i], 0.0);
        }
      // x^T M^{-1} y = y^T M^{-1} x, and x_F^T M_FF^{-1} x_F > 0.
      EXPECT_NEAR(x.dot(zy), y.dot(zx), 1e-12 * x.norm() * zy.norm());
      EXPECT_GT(x.dot(zx), 0.0);
    }
  }
}

}  // namespace
