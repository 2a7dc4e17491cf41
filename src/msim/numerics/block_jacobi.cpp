// GCC 12 reports Eigen's AVX-512 kernels for fixed 6 x 6 blocks as reading an uninitialised register
// (GCC bug 105593, the _mm512_undefined intrinsics; fixed in GCC 13): a false positive.
#if defined(__GNUC__) && !defined(__clang__) && __GNUC__ < 13
#pragma GCC diagnostic ignored "-Wmaybe-uninitialized"
#endif

#include "msim/numerics/block_jacobi.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include <Eigen/Dense>
#include <tbb/enumerable_thread_specific.h>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

void parallelMultiply(const SparseRowMatrix& A, const Eigen::VectorXd& x, Eigen::VectorXd& y) {
  y.resize(A.rows());
  const int* outer = A.outerIndexPtr();
  const int* inner = A.innerIndexPtr();
  const double* value = A.valuePtr();
  parallelFor(0, static_cast<std::size_t>(A.rows()), [&](std::size_t row) {
    double s = 0.0;
    for (int e = outer[row]; e < outer[row + 1]; ++e) s += value[e] * x[inner[e]];
    y[static_cast<Eigen::Index>(row)] = s;
  }, 256);
}

SparseRowMatrix parallelProduct(const SparseRowMatrix& A, const SparseRowMatrix& B) {
  if (A.cols() != B.rows()) throw std::invalid_argument("sparse product: the inner sizes differ");
  const auto rows = static_cast<std::size_t>(A.rows());
  const int* aOuter = A.outerIndexPtr();
  const int* aInner = A.innerIndexPtr();
  const double* aValue = A.valuePtr();
  const int* bOuter = B.outerIndexPtr();
  const int* bInner = B.innerIndexPtr();
  const double* bValue = B.valuePtr();
  // Per thread: the slot of each column in the row being formed (-1: none yet).
  tbb::enumerable_thread_specific<std::vector<int>> slots([&] { return std::vector<int>(static_cast<std::size_t>(B.cols()), -1); });
  // Pass 1: the nonzeros of each row.
  std::vector<int> count(rows + 1, 0);
  parallelFor(0, rows, [&](std::size_t row) {
    std::vector<int>& slot = slots.local();
    int n = 0;
    for (int e = aOuter[row]; e < aOuter[row + 1]; ++e)
      for (int f = bOuter[aInner[e]]; f < bOuter[aInner[e] + 1]; ++f)
        if (slot[static_cast<std::size_t>(bInner[f])] != static_cast<int>(row)) {
          slot[static_cast<std::size_t>(bInner[f])] = static_cast<int>(row);
          ++n;
        }
    count[row + 1] = n;
  }, 64);
  for (std::size_t row = 0; row < rows; ++row) count[row + 1] += count[row];
  SparseRowMatrix C(A.rows(), B.cols());
  C.resizeNonZeros(count[rows]);
  std::copy(count.begin(), count.end(), C.outerIndexPtr());
  int* cInner = C.innerIndexPtr();
  double* cValue = C.valuePtr();
  // Pass 2: the values, accumulated in place, then each row's columns sorted.
  for (std::vector<int>& slot : slots) std::fill(slot.begin(), slot.end(), -1);  // pass 1 left row numbers
  tbb::enumerable_thread_specific<std::vector<std::pair<int, double>>> rowBuffers;
  parallelFor(0, rows, [&](std::size_t row) {
    std::vector<int>& slot = slots.local();
    const int begin = count[row];
    int end = begin;
    for (int e = aOuter[row]; e < aOuter[row + 1]; ++e)
      for (int f = bOuter[aInner[e]]; f < bOuter[aInner[e] + 1]; ++f) {
        const auto column = static_cast<std::size_t>(bInner[f]);
        if (slot[column] < begin || slot[column] >= end) {  // not yet in this row (rows' ranges are disjoint)
          slot[column] = end;
          cInner[end] = bInner[f];
          cValue[end++] = 0.0;
        }
        cValue[slot[column]] += aValue[e] * bValue[f];
      }
    std::vector<std::pair<int, double>>& sorted = rowBuffers.local();
    sorted.clear();
    for (int e = begin; e < end; ++e) sorted.emplace_back(cInner[e], cValue[e]);
    std::sort(sorted.begin(), sorted.end(), [](const auto& x, const auto& y) { return x.first < y.first; });
    for (int e = begin; e < end; ++e) {
      cInner[e] = sorted[static_cast<std::size_t>(e - begin)].first;
      cValue[e] = sorted[static_cast<std::size_t>(e - begin)].second;
    }
  }, 64);
  return C;
}

double parallelDot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return parallelSum(static_cast<std::size_t>(a.size()),
                     [&](std::size_t i) { return a[static_cast<Eigen::Index>(i)] * b[static_cast<Eigen::Index>(i)]; });
}

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
  const int b = blockSize_;
  z.resize(r.size());
  parallelFor(0, static_cast<std::size_t>(r.size() / b), [&](std::size_t node) {
    const auto i = static_cast<Eigen::Index>(node);
    const double* m = inverse_.data() + node * static_cast<std::size_t>(b * b);
    for (int k = 0; k < b; ++k) {
      double s = 0.0;
      for (int l = 0; l < b; ++l) s += m[l * b + k] * r[i * b + l];
      z[i * b + k] = s;
    }
  }, 512);
}

}  // namespace msim::numerics
