#pragma once
// Block-diagonal (block-Jacobi) preconditioning of sparse systems whose unknowns come in blocks of
// b = 1-6 per node: D holds each node's b x b diagonal block, and D^-1 r couples a node's components as
// its own block does (a spring's stiffness along its direction, not along the axes). Used on its
// own as the cheap preconditioner of small systems and as the smoother of smoothed_aggregation.hpp.
#include <span>
#include <vector>

#include "msim/numerics/sparse_ops.hpp"
#include "msim/numerics/symmetric_block_matrix.hpp"

namespace msim::numerics {

class BlockJacobi {
 public:
  // D^-1 of A's b x b diagonal blocks (b = 1-6); std::invalid_argument if one is not positive
  // definite.
  void setup(const SparseRowMatrix& A, int blockSize);
  // The same with b = 3 from a symmetric block matrix's diagonal blocks (on all cores).
  void setup(const SymmetricBlockMatrix& A);
  // Only the blocks of `rows` (a solve split among processes, whose other rows' residuals stay 0);
  // the others keep their last values, 0 at first.
  void setup(const SymmetricBlockMatrix& A, std::span<const int> rows);
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
