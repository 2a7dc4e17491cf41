#include "msim/numerics/symmetric_block_matrix.hpp"

#include <algorithm>
#include <atomic>
#include <stdexcept>

#if defined(__AVX2__) && defined(__FMA__)
#include <immintrin.h>
#endif

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// Rows per task: a few thousand particles' blocks, enough to hide the threads' start.
constexpr std::size_t kRowGrain = 2048;

}  // namespace

void SymmetricBlockMatrix::setPattern(std::vector<int> rowStart, std::vector<int> columns) {
  if (rowStart.empty() || rowStart.front() != 0 || static_cast<std::size_t>(rowStart.back()) != columns.size())
    throw std::invalid_argument("SymmetricBlockMatrix: row starts do not span the columns");
  const int n = static_cast<int>(rowStart.size()) - 1;
  for (int r = 0; r < n; ++r) {
    if (rowStart[r + 1] < rowStart[r]) throw std::invalid_argument("SymmetricBlockMatrix: row starts decrease");
    for (int e = rowStart[r]; e < rowStart[r + 1]; ++e) {
      if (columns[e] < 0 || columns[e] >= n || columns[e] == r)
        throw std::invalid_argument("SymmetricBlockMatrix: an off-diagonal column lies outside or on the diagonal");
      if (e > rowStart[r] && columns[e] <= columns[e - 1])
        throw std::invalid_argument("SymmetricBlockMatrix: a row's columns are not sorted and distinct");
    }
  }
  rowStart_ = std::move(rowStart);
  columns_ = std::move(columns);
  diagonal_.assign(static_cast<std::size_t>(n), SymmetricBlock<double>{});
  // One block more than the pattern's: the four-wide product reads eight floats from each block.
  blocks_.assign(columns_.size() + 1, SymmetricBlock<float>{});
}

int SymmetricBlockMatrix::find(int row, int column) const {
  const auto begin = columns_.begin() + rowStart_[static_cast<std::size_t>(row)];
  const auto end = columns_.begin() + rowStart_[static_cast<std::size_t>(row) + 1];
  const auto it = std::lower_bound(begin, end, column);
  return it != end && *it == column ? static_cast<int>(it - columns_.begin()) : -1;
}

void SymmetricBlockMatrix::setRow(std::size_t r, const SymmetricBlock<double>& diagonal,
                                  std::span<const SymmetricBlock<double>> offDiagonal) {
  const std::span<SymmetricBlock<float>> rounded(blocks_.data() + rowStart_[r], offDiagonal.size());
  for (std::size_t i = 0; i < offDiagonal.size(); ++i) {
    const SymmetricBlock<double>& e = offDiagonal[i];
    rounded[i] = {static_cast<float>(e.xx), static_cast<float>(e.yy), static_cast<float>(e.zz),
                  static_cast<float>(e.xy), static_cast<float>(e.xz), static_cast<float>(e.yz)};
  }
  // The rounding is read back from memory: GCC 12's vectoriser folds double(float(x)) - x to zero
  // with AVX when the stored value is forwarded (the fence keeps it from forwarding).
  std::atomic_signal_fence(std::memory_order_seq_cst);
  SymmetricBlock<double> d = diagonal;
  for (std::size_t i = 0; i < offDiagonal.size(); ++i) {
    const SymmetricBlock<double>& e = offDiagonal[i];
    const SymmetricBlock<float>& f = rounded[i];
    d.xx += e.xx - f.xx, d.yy += e.yy - f.yy, d.zz += e.zz - f.zz;
    d.xy += e.xy - f.xy, d.xz += e.xz - f.xz, d.yz += e.yz - f.yz;
  }
  diagonal_[r] = d;
}

void SymmetricBlockMatrix::multiply(const Eigen::VectorXd& u, Eigen::VectorXd& y) const {
  y.resize(static_cast<Eigen::Index>(3 * rows()));
  multiply(u.data(), y.data());
}

void SymmetricBlockMatrix::multiplyRow(std::size_t r, const double* in, double* out) const {
  const SymmetricBlock<double>& d = diagonal_[r];
  const double* own = in + 3 * r;
  double x = d.xx * own[0] + d.xy * own[1] + d.xz * own[2];
  double y = d.xy * own[0] + d.yy * own[1] + d.yz * own[2];
  double z = d.xz * own[0] + d.yz * own[1] + d.zz * own[2];
#if defined(__AVX2__) && defined(__FMA__)
  // Each block's three columns in four-wide registers: one load of its six floats (and two of the
  // next block's, or of the padding after the last), two permutes and three conversions give
  // (xx, xy, xz), (xy, yy, yz) and (xz, yz, zz); the product is then three multiply-adds, a third of
  // the scalar path's arithmetic (the scalar path below serves the portable build).
  const __m256i firstColumns = _mm256_setr_epi32(0, 3, 4, 4, 3, 1, 5, 5);  // (xx xy xz), (xy yy yz)
  const __m256i thirdColumn = _mm256_setr_epi32(4, 5, 2, 2, 4, 5, 2, 2);   // (xz yz zz)
  const auto blockProduct = [&](int e) {
    const __m256 packed = _mm256_loadu_ps(&blocks_[static_cast<std::size_t>(e)].xx);
    const __m256 columns01 = _mm256_permutevar8x32_ps(packed, firstColumns);
    const __m256d column0 = _mm256_cvtps_pd(_mm256_castps256_ps128(columns01));
    const __m256d column1 = _mm256_cvtps_pd(_mm256_extractf128_ps(columns01, 1));
    const __m256d column2 = _mm256_cvtps_pd(_mm256_castps256_ps128(_mm256_permutevar8x32_ps(packed, thirdColumn)));
    const double* v = in + 3 * static_cast<std::size_t>(columns_[static_cast<std::size_t>(e)]);
    return _mm256_fmadd_pd(column2, _mm256_broadcast_sd(v + 2),
                           _mm256_fmadd_pd(column1, _mm256_broadcast_sd(v + 1), _mm256_mul_pd(column0, _mm256_broadcast_sd(v))));
  };
  __m256d sum = _mm256_setr_pd(x, y, z, 0.0);
  for (int e = rowStart_[r]; e < rowStart_[r + 1]; ++e) sum = _mm256_add_pd(sum, blockProduct(e));
  _mm_storeu_pd(out + 3 * r, _mm256_castpd256_pd128(sum));
  _mm_store_sd(out + 3 * r + 2, _mm256_extractf128_pd(sum, 1));
#else
  for (int e = rowStart_[r]; e < rowStart_[r + 1]; ++e) {
    const SymmetricBlock<float>& b = blocks_[static_cast<std::size_t>(e)];
    const double* v = in + 3 * static_cast<std::size_t>(columns_[static_cast<std::size_t>(e)]);
    x += b.xx * v[0] + b.xy * v[1] + b.xz * v[2];
    y += b.xy * v[0] + b.yy * v[1] + b.yz * v[2];
    z += b.xz * v[0] + b.yz * v[1] + b.zz * v[2];
  }
  out[3 * r] = x, out[3 * r + 1] = y, out[3 * r + 2] = z;
#endif
}

void SymmetricBlockMatrix::multiply(const double* in, double* out) const {
  parallelFor(0, rows(), [&](std::size_t r) { multiplyRow(r, in, out); }, kRowGrain);
}

void SymmetricBlockMatrix::multiplyRows(const double* in, double* out, std::span<const int> which) const {
  parallelFor(0, which.size(), [&](std::size_t k) { multiplyRow(static_cast<std::size_t>(which[k]), in, out); }, kRowGrain);
}

SparseRowMatrix SymmetricBlockMatrix::expanded() const {
  const auto n = static_cast<Eigen::Index>(3 * rows());
  SparseRowMatrix A(n, n);
  A.resizeNonZeros(static_cast<Eigen::Index>(9 * (columns_.size() + rows())));
  int* outer = A.outerIndexPtr();
  int* inner = A.innerIndexPtr();
  double* value = A.valuePtr();
  int entry = 0;
  for (std::size_t r = 0; r < rows(); ++r) {
    const Eigen::Matrix3d own = diagonal_[r].matrix();
    for (int k = 0; k < 3; ++k) {
      outer[3 * r + static_cast<std::size_t>(k)] = entry;
      bool ownWritten = false;
      const auto write = [&](int column, const Eigen::Matrix3d& m) {
        for (int l = 0; l < 3; ++l) {
          inner[entry] = 3 * column + l;
          value[entry++] = m(k, l);
        }
      };
      for (int e = rowStart_[r]; e < rowStart_[r + 1]; ++e) {
        const int column = columns_[static_cast<std::size_t>(e)];
        if (!ownWritten && column > static_cast<int>(r)) {
          write(static_cast<int>(r), own);
          ownWritten = true;
        }
        const SymmetricBlock<float>& b = blocks_[static_cast<std::size_t>(e)];
        write(column, SymmetricBlock<double>{b.xx, b.yy, b.zz, b.xy, b.xz, b.yz}.matrix());
      }
      if (!ownWritten) write(static_cast<int>(r), own);
    }
  }
  outer[n] = entry;
  return A;
}

}  // namespace msim::numerics
