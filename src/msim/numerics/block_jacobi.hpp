#pragma once
// Block-diagonal (block-Jacobi) preconditioning of sparse systems whose unknowns come in blocks of
// b = 1-6 per node: D holds each node's b x b diagonal block, and D^-1 r couples a node's components as
// its own block does (a spring's stiffness along its direction, not along the axes). Used on its
// own as the cheap preconditioner of small systems and as the smoother of smoothed_aggregation.hpp.
#include <vector>

#include <Eigen/Sparse>

namespace msim::numerics {

using SparseRowMatrix = Eigen::SparseMatrix<double, Eigen::RowMajor>;

// y = A x, the rows shared among threads (A compressed).
void parallelMultiply(const SparseRowMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y);
// C = A B by rows on all cores (Gustavson's row-by-row accumulation), columns sorted in each row.
SparseRowMatrix parallelProduct(const SparseRowMatrix& A, const SparseRowMatrix& B);
// Deterministic parallel dot product (fixed blocks, whatever the thread count).
double parallelDot(const Eigen::VectorXd& a, const Eigen::VectorXd& b);

class BlockJacobi {
 public:
  // D^-1 of A's b x b diagonal blocks (b = 1-6); std::invalid_argument if one is not positive
  // definite.
  void setup(const SparseRowMatrix& A, int blockSize);
  // z = D^-1 r (z resized; r and z must differ).
  void apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const;
  int blockSize() const { return blockSize_; }
  // D^-1 as a block-diagonal sparse matrix.
  SparseRowMatrix inverseMatrix() const;

 private:
  int blockSize_ = 1;
  std::vector<double> inverse_;  // b x b per node, column-major
};

}  // namespace msim::numerics
