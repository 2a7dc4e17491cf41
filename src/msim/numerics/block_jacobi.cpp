// GCC 12 reports Eigen's AVX-512 kernels for fixed 6 x 6 blocks as reading an uninitialised register
// (GCC bug 105593, the _mm512_undefined intrinsics; fixed in GCC 13): a false positive.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "msim/numerics/block_jacobi.hpp"

#include <atomic>
#include <stdexcept>
#include <vector>

#include <Eigen/Dense>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// The inverse of each b x b diagonal block (fixed sizes: unrolled kernels).
template <int B>
void invertDiagonalBlocks(const SparseRowMatrix& A, std::vector<double>& inverse) {
  using Block = Eigen::Matrix<double, B, B>;
  const Eigen::Index n = A.rows() / B;
  inverse.resize(static_cast<std::size_t>(n * B * B));
  for (Eigen::Index i = 0; i < n; ++i) {
    Block block = Block::Zero();
    for (int k = 0; k < B; ++k)
      for (SparseRowMatrix::InnerIterator it(A, i * B + k); it; ++it)
        if (it.col() / B == i) block(k, static_cast<int>(it.col() - i * B)) = it.value();
    const Eigen::LLT<Block> llt(block);
    if (llt.info() != Eigen::Success)
      throw std::invalid_argument("block Jacobi: a diagonal block is not positive definite");
    Eigen::Map<Block>(inverse.data() + i * B * B) = llt.solve(Block::Identity());
  }
}

// z = D^-1 r with the block size known at compile time (fixed-size products, unrolled).
template <int B>
void applyBlocks(const std::vector<double>& inverse, const Eigen::VectorXd& r, Eigen::VectorXd& z) {
  using Block = Eigen::Matrix<double, B, B>;
  using Part = Eigen::Matrix<double, B, 1>;
  parallelFor(0, static_cast<std::size_t>(r.size() / B), [&](std::size_t node) {
    const auto i = static_cast<Eigen::Index>(node) * B;
    z.segment<B>(i).noalias() = Eigen::Map<const Block>(inverse.data() + node * B * B) * Part(r.segment<B>(i));
  }, 2048);
}

// The inverses of the diagonal blocks row(k), k < count, of a symmetric block matrix, on all cores
// (the others keep their values, 0 at first); std::invalid_argument if one is not positive definite.
template <typename Row>
void invertSymmetricBlocks(const SymmetricBlockMatrix& A, std::size_t count, Row&& row, std::vector<double>& inverse) {
  inverse.resize(9 * A.rows());
  std::atomic<bool> indefinite = false;
  parallelFor(0, count, [&](std::size_t k) {
    const std::size_t r = row(k);
    const Eigen::LLT<Eigen::Matrix3d> llt(A.diagonal(r).matrix());
    if (llt.info() != Eigen::Success) indefinite = true;
    else Eigen::Map<Eigen::Matrix3d>(inverse.data() + 9 * r) = llt.solve(Eigen::Matrix3d::Identity());
  }, 2048);
  if (indefinite) throw std::invalid_argument("block Jacobi: a diagonal block is not positive definite");
}

}  // namespace

void BlockJacobi::setup(const SparseRowMatrix& A, int blockSize) {
  if ((blockSize != 1 && blockSize != 3 && blockSize != 6) || A.rows() != A.cols() || A.rows() % blockSize != 0)
    throw std::invalid_argument("block Jacobi: the matrix must be square and of whole blocks of 1, 3 or 6 unknowns");
  blockSize_ = blockSize;
  switch (blockSize) {
    case 1: invertDiagonalBlocks<1>(A, inverse_); break;
    case 3: invertDiagonalBlocks<3>(A, inverse_); break;
    default: invertDiagonalBlocks<6>(A, inverse_); break;
  }
}

void BlockJacobi::setup(const SymmetricBlockMatrix& A) {
  invertSymmetricBlocks(A, A.rows(), [](std::size_t k) { return k; }, inverse_);
  blockSize_ = 3;
}

void BlockJacobi::setup(const SymmetricBlockMatrix& A, std::span<const int> rows) {
  invertSymmetricBlocks(A, rows.size(), [&](std::size_t k) { return static_cast<std::size_t>(rows[k]); }, inverse_);
  blockSize_ = 3;
}

SparseRowMatrix BlockJacobi::inverseMatrix() const {
  const int b = blockSize_;
  const auto n = static_cast<Eigen::Index>(inverse_.size()) / (b * b);
  std::vector<Eigen::Triplet<double>> entries;
  entries.reserve(inverse_.size());
  for (Eigen::Index i = 0; i < n; ++i)
    for (int k = 0; k < b; ++k)
      for (int l = 0; l < b; ++l) entries.emplace_back(i * b + k, i * b + l, inverse_[static_cast<std::size_t>(i * b * b + l * b + k)]);
  SparseRowMatrix inverse(n * b, n * b);
  inverse.setFromTriplets(entries.begin(), entries.end());
  return inverse;
}

void BlockJacobi::apply(const Eigen::VectorXd& r, Eigen::VectorXd& z) const {
  z.resize(r.size());
  switch (blockSize_) {
    case 1: applyBlocks<1>(inverse_, r, z); break;
    case 3: applyBlocks<3>(inverse_, r, z); break;
    default: applyBlocks<6>(inverse_, r, z); break;
  }
}

}  // namespace msim::numerics
