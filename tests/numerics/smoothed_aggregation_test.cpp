// Smoothed-aggregation multigrid as a conjugate-gradient preconditioner: iteration counts that stay
// nearly flat as the grid is refined (where block Jacobi's grow with the grid's width), exact answers,
// a symmetric V-cycle, and clear errors on matrices it cannot take.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <stdexcept>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/numerics/smoothed_aggregation.hpp"
#include "msim/numerics/sparse_cg.hpp"

namespace msim::numerics {
namespace {

// The 5-point Laplacian of an n x n grid with Dirichlet walls.
SparseRowMatrix poisson(int n) {
  std::vector<Eigen::Triplet<double>> entries;
  const auto id = [n](int i, int j) { return j * n + i; };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      entries.emplace_back(id(i, j), id(i, j), 4.0);
      if (i > 0) entries.emplace_back(id(i, j), id(i - 1, j), -1.0);
      if (i + 1 < n) entries.emplace_back(id(i, j), id(i + 1, j), -1.0);
      if (j > 0) entries.emplace_back(id(i, j), id(i, j - 1), -1.0);
      if (j + 1 < n) entries.emplace_back(id(i, j), id(i, j + 1), -1.0);
    }
  SparseRowMatrix A(n * n, n * n);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

// A cloth-like spring network in 3D: an n x n grid of particles in a tilted plane, springs along the
// edges and one diagonal of each quad, each k d d^T on its two particles, plus mass m I. The first
// row of particles is pinned: identity rows, uncoupled.
Eigen::Vector3d networkPoint(int n, int i, int j) {
  const Eigen::Vector3d u(1.0, 0.3, 0.0), v(0.0, 0.4, 1.0);
  return (double(i) * u + double(j) * v) / double(n);
}

SparseRowMatrix springNetwork(int n, double mass) {
  const auto position = [n](int i, int j) { return networkPoint(n, i, j); };
  const auto id = [n](int i, int j) { return j * n + i; };
  std::vector<Eigen::Triplet<double>> entries;
  const auto pinned = [&](int node) { return node < n; };
  const auto add = [&](int a, int b, const Eigen::Matrix3d& block) {
    if (pinned(a) || pinned(b)) return;
    for (int k = 0; k < 3; ++k)
      for (int l = 0; l < 3; ++l) entries.emplace_back(3 * a + k, 3 * b + l, block(k, l));
  };
  const auto spring = [&](int i0, int j0, int i1, int j1) {
    const Eigen::Vector3d d = (position(i1, j1) - position(i0, j0)).normalized();
    const Eigen::Matrix3d K = double(n) * d * d.transpose();  // k / l0 with l0 ~ 1 / n
    const int a = id(i0, j0), b = id(i1, j1);
    add(a, a, K);
    add(b, b, K);
    add(a, b, -K);
    add(b, a, -K);
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if (i + 1 < n) spring(i, j, i + 1, j);
      if (j + 1 < n) spring(i, j, i, j + 1);
      if (i + 1 < n && j + 1 < n) spring(i, j, i + 1, j + 1);
      const int a = id(i, j);
      for (int k = 0; k < 3; ++k) entries.emplace_back(3 * a + k, 3 * a + k, pinned(a) ? 1.0 : mass);
    }
  SparseRowMatrix A(3 * n * n, 3 * n * n);
  A.setFromTriplets(entries.begin(), entries.end());
  return A;
}

struct Solve {
  int iterations = 0;
  double error = 0.0;  // relative to the known answer
};

template <typename Preconditioner>
Solve solve(const SparseRowMatrix& A, const Preconditioner& preconditioner) {
  Rng rng(7);
  Eigen::VectorXd answer(A.rows());
  for (Eigen::Index i = 0; i < answer.size(); ++i) answer[i] = rng.normal();
  const Eigen::VectorXd rhs = A * answer;
  Eigen::VectorXd x = Eigen::VectorXd::Zero(A.rows()), r = rhs;
  SparseCgWorkspace workspace;
  const auto product = [&A](const Eigen::VectorXd& u, Eigen::VectorXd& y) { parallelMultiply(A, u, y); };
  const SparseCgStats stats = preconditionedCg(product, preconditioner, x, r, 1e-20 * parallelDot(rhs, rhs), 5000, workspace);
  EXPECT_TRUE(stats.converged);
  const Eigen::VectorXd error = x - answer;
  return {stats.iterations, std::sqrt(parallelDot(error, error) / parallelDot(answer, answer))};
}

TEST(SmoothedAggregation, PoissonIterationsStayNearlyFlatAsTheGridIsRefined) {
  std::vector<int> multigrid, jacobi;
  for (int n : {32, 64, 128, 256}) {
    const SparseRowMatrix A = poisson(n);
    SmoothedAggregation amg;
    amg.setup(A);
    BlockJacobi diagonal;
    diagonal.setup(A, 1);
    const Solve a = solve(A, amg), d = solve(A, diagonal);
    EXPECT_LT(a.error, 1e-7) << n;
    EXPECT_LT(d.error, 1e-7) << n;
    EXPECT_LT(amg.operatorComplexity(), 2.0) << n;
    multigrid.push_back(a.iterations);
    jacobi.push_back(d.iterations);
  }
  // Jacobi-preconditioned CG needs iterations in proportion to the grid's width (the condition
  // number grows with n^2); the multigrid-preconditioned count grows far slower.
  std::printf("Poisson 32^2..256^2: multigrid %d %d %d %d, Jacobi %d %d %d %d iterations\n", multigrid[0], multigrid[1],
              multigrid[2], multigrid[3], jacobi[0], jacobi[1], jacobi[2], jacobi[3]);
  EXPECT_GT(jacobi.back(), 5 * jacobi.front());
  EXPECT_LT(multigrid.back(), 2 * multigrid.front());
  EXPECT_LT(multigrid.back(), 40);
  EXPECT_LT(4 * multigrid.back(), jacobi.back());
}

TEST(SmoothedAggregation, StiffSpringNetworkWithPinnedRowsSolvesInFewIterations) {
  std::vector<int> multigrid;
  for (int n : {24, 48, 96}) {
    const SparseRowMatrix A = springNetwork(n, 1e-4);
    SmoothedAggregation amg(AggregationSettings{.blockSize = 3});
    amg.setup(A);
    BlockJacobi diagonal;
    diagonal.setup(A, 3);
    const Solve a = solve(A, amg), d = solve(A, diagonal);
    EXPECT_LT(a.error, 1e-6) << n;
    multigrid.push_back(a.iterations);
    std::printf("springs %d^2: multigrid %d, block Jacobi %d iterations, %d levels\n", n, a.iterations, d.iterations, amg.levels());
    EXPECT_LT(3 * a.iterations, d.iterations) << n;
  }
  EXPECT_LT(multigrid.back(), 3 * multigrid.front());
}

// Springs that are not stretched resist no small rotation, so the network's near-null space holds the
// rotations too: coarse levels that carry them (rigidModes) take far fewer iterations than
// translations alone.
TEST(SmoothedAggregation, RotationsInTheNearNullSpaceHelpSprings) {
  const int n = 96;
  const SparseRowMatrix A = springNetwork(n, 1e-4);
  std::vector<Eigen::Vector3d> points;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) points.push_back(networkPoint(n, i, j));
  SmoothedAggregation translations(AggregationSettings{.blockSize = 3}), rigid(AggregationSettings{.blockSize = 3});
  translations.setup(A);
  rigid.setup(A, rigidModes(points, Eigen::Vector3d(0.5, 0.35, 0.5)));
  const Solve t = solve(A, translations), r = solve(A, rigid);
  std::printf("springs %d^2: translations %d, rigid modes %d iterations\n", n, t.iterations, r.iterations);
  EXPECT_LT(r.error, 1e-6);
  EXPECT_LT(3 * r.iterations, 2 * t.iterations);
}

TEST(SmoothedAggregation, VCycleIsSymmetric) {
  const SparseRowMatrix A = springNetwork(40, 1e-3);
  SmoothedAggregation amg(AggregationSettings{.blockSize = 3});
  amg.setup(A);
  ASSERT_GE(amg.levels(), 3);
  Rng rng(3);
  Eigen::VectorXd x(A.rows()), y(A.rows()), Mx, My;
  for (Eigen::Index i = 0; i < x.size(); ++i) {
    x[i] = rng.normal();
    y[i] = rng.normal();
  }
  amg.apply(x, Mx);
  amg.apply(y, My);
  EXPECT_NEAR(parallelDot(y, Mx), parallelDot(x, My), 1e-10 * std::abs(parallelDot(y, Mx)) + 1e-14);
  EXPECT_GT(parallelDot(x, Mx), 0.0);
}

TEST(SmoothedAggregation, RejectsMatricesItCannotTake) {
  SmoothedAggregation amg(AggregationSettings{.blockSize = 3});
  EXPECT_THROW(amg.setup(poisson(4)), std::invalid_argument);  // 16 rows: not whole 3 x 3 blocks
  SparseRowMatrix indefinite = poisson(6);
  indefinite.coeffRef(5, 5) = -1.0;
  SmoothedAggregation scalar;
  EXPECT_THROW(scalar.setup(indefinite), std::invalid_argument);
  EXPECT_THROW(SmoothedAggregation(AggregationSettings{.blockSize = 0}), std::invalid_argument);
  EXPECT_THROW(SmoothedAggregation(AggregationSettings{.blockSize = 7}), std::invalid_argument);
}

}  // namespace
}  // namespace msim::numerics
