#pragma once
// A sparse matrix of 3 x 3 blocks each of which is symmetric: the matrices of mass-spring solves,
// where every spring couples its particles by a multiple of the symmetric c d d^T + c' (I - d d^T).
// The off-diagonal blocks are stored as six floats, a quarter of the bytes of the same blocks as
// 3 x 3 doubles in scalar CSR, which is what a memory-bound product over a cloth of 100k triangles
// pays for; the diagonal blocks stay double and absorb the rounding of their row (setRow), so the
// rounded matrix applies to a vector that is the same at every node (a rigid translation) exactly
// as the exact one: a moving cloth is not damped by rounding. A row is one thread's in the product,
// so it gives the same result whatever the thread count. block_jacobi.hpp preconditions it.
#include <cstddef>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "msim/numerics/sparse_ops.hpp"

namespace msim::numerics {

// A symmetric 3 x 3 block: xx, yy, zz, xy, xz, yz.
template <typename T>
struct SymmetricBlock {
  T xx = 0, yy = 0, zz = 0, xy = 0, xz = 0, yz = 0;
  Eigen::Matrix3d matrix() const {
    Eigen::Matrix3d m;
    m << xx, xy, xz, xy, yy, yz, xz, yz, zz;
    return m;
  }
};

class SymmetricBlockMatrix {
 public:
  // The off-diagonal pattern: block row r holds the block columns columns[rowStart[r] ..
  // rowStart[r + 1]), sorted ascending, r itself not among them; values zero.
  // std::invalid_argument if a row is unsorted or holds its own column, or a column is out of range.
  void setPattern(std::vector<int> rowStart, std::vector<int> columns);
  std::size_t rows() const { return rowStart_.empty() ? 0 : rowStart_.size() - 1; }
  // The off-diagonal entry of block (row, column), or -1 outside the pattern.
  int find(int row, int column) const;
  std::span<const int> rowStart() const { return rowStart_; }
  std::span<const int> columns() const { return columns_; }

  // Row r's values: its diagonal block and its off-diagonal blocks in the pattern's order, exact;
  // the latter are rounded to float and their rounding is added to the diagonal. For a symmetric
  // matrix the rounded one stays symmetric when each pair (r, c), (c, r) is given the same block.
  void setRow(std::size_t r, const SymmetricBlock<double>& diagonal, std::span<const SymmetricBlock<double>> offDiagonal);
  const SymmetricBlock<double>& diagonal(std::size_t r) const { return diagonal_[r]; }

  // y = A u; u and y hold 3 values per block row and must differ (y resized).
  void multiply(const Eigen::VectorXd& u, Eigen::VectorXd& y) const;
  void multiply(const double* u, double* y) const;  // 3 rows() values each
  // Rows `which` of y = A u only (a solve split among processes computes its own rows).
  void multiplyRows(const double* u, double* y, std::span<const int> which) const;
  // The same matrix in scalar CSR, 3 x 3 entries per block (for multigrid setups).
  SparseRowMatrix expanded() const;

 private:
  void multiplyRow(std::size_t r, const double* u, double* y) const;

  std::vector<int> rowStart_, columns_;
  std::vector<SymmetricBlock<double>> diagonal_;
  std::vector<SymmetricBlock<float>> blocks_;  // the pattern's, and one of padding (multiply's wide loads)
};

}  // namespace msim::numerics
