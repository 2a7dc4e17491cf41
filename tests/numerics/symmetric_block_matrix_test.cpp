// The float-block matrix of mass-spring solves (symmetric_block_matrix.hpp) against the same matrix
// held exactly in double: the product within float rounding, exactly symmetric, a uniform vector
// (a rigid translation) applied as exactly as in double, block-Jacobi (block_jacobi.hpp) inverting
// its diagonal blocks, the expanded CSR equal to the product, and patterns that are not sorted refused.
#include <gtest/gtest.h>

#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "msim/core/rng.hpp"
#include "msim/numerics/block_jacobi.hpp"
#include "msim/numerics/symmetric_block_matrix.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

using Block = SymmetricBlock<double>;

Block fromMatrix(const Eigen::Matrix3d& m) { return {m(0, 0), m(1, 1), m(2, 2), m(0, 1), m(0, 2), m(1, 2)}; }

// A chain of n particles with springs to the next two (a 1D cloth strip with bending springs):
// each spring k d d^T on its pair, masses on the diagonal. Returns the exact dense matrix too.
struct Chain {
  SymmetricBlockMatrix matrix;
  Eigen::MatrixXd dense;
};

Chain springChain(int n, Rng& rng) {
  std::vector<int> rowStart(1, 0), columns;
  for (int r = 0; r < n; ++r) {
    for (int c = std::max(0, r - 2); c <= std::min(n - 1, r + 2); ++c)
      if (c != r) columns.push_back(c);
    rowStart.push_back(static_cast<int>(columns.size()));
  }
  Chain chain;
  chain.matrix.setPattern(rowStart, columns);
  chain.dense = Eigen::MatrixXd::Zero(3 * n, 3 * n);
  std::vector<Block> diagonal(static_cast<std::size_t>(n));
  std::vector<std::vector<Block>> off(static_cast<std::size_t>(n));
  for (int r = 0; r < n; ++r) off[static_cast<std::size_t>(r)].assign(static_cast<std::size_t>(rowStart[r + 1] - rowStart[r]), Block{});
  for (int r = 0; r < n; ++r) {
    const double mass = 0.01 * (1.0 + rng.uniform());
    chain.dense.block<3, 3>(3 * r, 3 * r) += mass * Eigen::Matrix3d::Identity();
  }
  for (int a = 0; a < n; ++a)
    for (int b = a + 1; b <= std::min(n - 1, a + 2); ++b) {
      const Eigen::Vector3d d = Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
      const Eigen::Matrix3d S = 0.3 * (1.0 + rng.uniform()) * d * d.transpose() + 0.01 * rng.uniform() * Eigen::Matrix3d::Identity();
      chain.dense.block<3, 3>(3 * a, 3 * a) += S;
      chain.dense.block<3, 3>(3 * b, 3 * b) += S;
      chain.dense.block<3, 3>(3 * a, 3 * b) -= S;
      chain.dense.block<3, 3>(3 * b, 3 * a) -= S;
    }
  for (int r = 0; r < n; ++r) {
    diagonal[static_cast<std::size_t>(r)] = fromMatrix(chain.dense.block<3, 3>(3 * r, 3 * r));
    for (int e = rowStart[r]; e < rowStart[r + 1]; ++e)
      off[static_cast<std::size_t>(r)][static_cast<std::size_t>(e - rowStart[r])] = fromMatrix(chain.dense.block<3, 3>(3 * r, 3 * columns[e]));
    chain.matrix.setRow(static_cast<std::size_t>(r), diagonal[static_cast<std::size_t>(r)], off[static_cast<std::size_t>(r)]);
  }
  return chain;
}

}  // namespace

TEST(SymmetricBlockMatrix, MultipliesAsTheExactMatrixWithinFloatRounding) {
  Rng rng(3);
  const Chain chain = springChain(200, rng);
  Eigen::VectorXd u(600);
  for (Eigen::Index i = 0; i < u.size(); ++i) u[i] = rng.normal();
  Eigen::VectorXd y;
  chain.matrix.multiply(u, y);
  const Eigen::VectorXd exact = chain.dense * u;
  EXPECT_LT((y - exact).norm(), 1e-6 * exact.norm());
  EXPECT_GT((y - exact).norm(), 0.0);  // the blocks are floats: not bitwise the double product
  // Symmetric: v . A u = u . A v exactly up to the sums' order.
  Eigen::VectorXd v(600), Av;
  for (Eigen::Index i = 0; i < v.size(); ++i) v[i] = rng.normal();
  chain.matrix.multiply(v, Av);
  EXPECT_NEAR(v.dot(y), u.dot(Av), 1e-12 * std::abs(v.dot(y)) + 1e-14);
  // The expanded CSR is the same matrix.
  const Eigen::VectorXd viaCsr = chain.matrix.expanded() * u;
  EXPECT_LT((viaCsr - y).norm(), 1e-13 * y.norm());
}

TEST(SymmetricBlockMatrix, AppliesARigidTranslationAsTheExactMatrix) {
  // Springs do not resist a translation: A c = M c. The float blocks alone would miss it by their
  // rounding (about 1e-8 of the springs); the diagonal absorbs it.
  Rng rng(5);
  const Chain chain = springChain(100, rng);
  Eigen::VectorXd c(300);
  for (int r = 0; r < 100; ++r) c.segment<3>(3 * r) = Eigen::Vector3d(0.3, 0.4, -0.2);
  Eigen::VectorXd y;
  chain.matrix.multiply(c, y);
  const Eigen::VectorXd exact = chain.dense * c;  // the masses times c
  EXPECT_LT((y - exact).lpNorm<Eigen::Infinity>(), 1e-15);
}

TEST(SymmetricBlockMatrix, BlockJacobiInvertsTheDiagonalBlocks) {
  Rng rng(7);
  const Chain chain = springChain(50, rng);
  BlockJacobi jacobi;
  jacobi.setup(chain.matrix);
  Eigen::VectorXd r(150), z;
  for (Eigen::Index i = 0; i < r.size(); ++i) r[i] = rng.normal();
  jacobi.apply(r, z);
  // The stored diagonal blocks (the exact ones plus their rows' float rounding) are inverted.
  for (int k = 0; k < 50; ++k) {
    const Eigen::Matrix3d D = chain.matrix.diagonal(static_cast<std::size_t>(k)).matrix();
    EXPECT_LT((D - chain.dense.block<3, 3>(3 * k, 3 * k)).norm(), 1e-6 * D.norm());
    EXPECT_LT((D * z.segment<3>(3 * k) - r.segment<3>(3 * k)).norm(), 1e-12 * r.segment<3>(3 * k).norm());
  }
  // An indefinite diagonal block is refused.
  SymmetricBlockMatrix bad;
  bad.setPattern({0, 0}, {});
  bad.setRow(0, Block{1.0, -1.0, 1.0, 0.0, 0.0, 0.0}, {});
  EXPECT_THROW(jacobi.setup(bad), std::invalid_argument);
}

TEST(SymmetricBlockMatrix, RefusesPatternsThatAreNotSortedOffDiagonalRows) {
  SymmetricBlockMatrix m;
  EXPECT_THROW(m.setPattern({0, 2, 2}, {1, 1}), std::invalid_argument);  // repeated
  EXPECT_THROW(m.setPattern({0, 1, 1}, {0}), std::invalid_argument);     // its own column
  EXPECT_THROW(m.setPattern({0, 1, 1}, {2}), std::invalid_argument);     // outside
  EXPECT_THROW(m.setPattern({0, 1}, {}), std::invalid_argument);         // starts past the columns
  m.setPattern({0, 1, 2}, {1, 0});
  EXPECT_EQ(m.find(0, 1), 0);
  EXPECT_EQ(m.find(1, 0), 1);
  EXPECT_EQ(m.find(0, 0), -1);
}
