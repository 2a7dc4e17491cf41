#pragma once
// Kernels on row-major sparse matrices and dense vectors that run on all cores: the products of
// conjugate gradients (sparse_cg.hpp) and the Galerkin products of multigrid setups
// (smoothed_aggregation.hpp).
#include <Eigen/Sparse>

namespace msim::numerics {

using SparseRowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// y = A x, the rows shared among threads (A compressed).
void parallelMultiply(const SparseRowMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y);
// C = A B by rows on all cores (Gustavson's row-by-row accumulation), columns sorted in each row.
SparseRowMatrix parallelProduct(const SparseRowMatrix& A, const SparseRowMatrix& B);
// Dot product, the same whatever the thread count (core/parallel.hpp's parallelSum).
double parallelDot(const Eigen::VectorXd& a, const Eigen::VectorXd& b);
// Conjugate gradients' update x += alpha s, r -= alpha q, returning the new |r|^2 (equal to
// parallelDot(r, r)), in one pass over the vectors on all cores.
double parallelStep(double alpha, const Eigen::VectorXd& s, const Eigen::VectorXd& q, Eigen::VectorXd& x, Eigen::VectorXd& r);
// s = z + beta s on all cores.
void parallelDirection(const Eigen::VectorXd& z, double beta, Eigen::VectorXd& s);

}  // namespace msim::numerics
