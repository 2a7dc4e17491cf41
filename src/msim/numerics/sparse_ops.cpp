#include "msim/numerics/sparse_ops.hpp"

#include <algorithm>
#include <stdexcept>
#include <utility>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/enumerable_thread_specific.h>
#include <tbb/parallel_reduce.h>

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

namespace {

// Blocks of fixed bounds, each summed with Eigen's vectorised kernels and joined along a fixed tree
// (tbb::parallel_deterministic_reduce): the same sum on every run and thread count, at the speed
// of SIMD on every core rather than of a serial chain of additions. f(first, length) -> double.
constexpr Eigen::Index kBlock = 4096;

template <typename F>
double blockSum(Eigen::Index size, F&& f) {
  const Eigen::Index blocks = (size + kBlock - 1) / kBlock;
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<Eigen::Index>(0, blocks, 1), 0.0,
      [&](const tbb::blocked_range<Eigen::Index>& r, double sum) {
        for (Eigen::Index block = r.begin(); block != r.end(); ++block) {
          const Eigen::Index first = block * kBlock;
          sum += f(first, std::min(kBlock, size - first));
        }
        return sum;
      },
      [](double x, double y) { return x + y; });
}

}  // namespace

double parallelDot(const Eigen::VectorXd& a, const Eigen::VectorXd& b) {
  return blockSum(a.size(), [&](Eigen::Index first, Eigen::Index length) {
    return a.segment(first, length).dot(b.segment(first, length));
  });
}

double parallelStep(double alpha, const Eigen::VectorXd& s, const Eigen::VectorXd& q, Eigen::VectorXd& x, Eigen::VectorXd& r) {
  return blockSum(r.size(), [&](Eigen::Index first, Eigen::Index length) {
    x.segment(first, length) += alpha * s.segment(first, length);
    auto block = r.segment(first, length);
    block -= alpha * q.segment(first, length);
    return block.squaredNorm();
  });
}

void parallelDirection(const Eigen::VectorXd& z, double beta, Eigen::VectorXd& s) {
  parallelFor(0, static_cast<std::size_t>((s.size() + kBlock - 1) / kBlock), [&](std::size_t block) {
    const auto first = static_cast<Eigen::Index>(block) * kBlock;
    const Eigen::Index length = std::min(kBlock, s.size() - first);
    s.segment(first, length) = z.segment(first, length) + beta * s.segment(first, length);
  }, 1);
}

}  // namespace msim::numerics
