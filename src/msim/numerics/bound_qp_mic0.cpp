#include "msim/numerics/bound_qp_mic0.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

namespace msim::numerics {

namespace {

// Validates the stencil arrays and returns the strides (x fastest).
template <int D>
std::array<std::size_t, D> checkStencil(const char* who, const IVec<D>& res,
                                        const std::array<std::vector<double>, D>& lower,
                                        const std::vector<double>& diagonal) {
  std::array<std::size_t, D> stride{};
  std::size_t n = 1;
  for (int a = 0; a < D; ++a) {
    if (res[a] < 1) throw std::invalid_argument(std::string(who) + ": resolution must be >= 1 per axis");
    stride[a] = n;
    n *= static_cast<std::size_t>(res[a]);
  }
  if (diagonal.size() != n)
    throw std::invalid_argument(std::string(who) + ": diagonal has " + std::to_string(diagonal.size()) +
                                " entries, grid has " + std::to_string(n) + " cells");
  for (int a = 0; a < D; ++a)
    if (lower[a].size() != n)
      throw std::invalid_argument(std::string(who) + ": lower weights of axis " + std::to_string(a) + " have " +
                                  std::to_string(lower[a].size()) + " entries, grid has " + std::to_string(n) +
                                  " cells");
  const bool ok = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 1 << 14), true,
      [&](const tbb::blocked_range<std::size_t>& r, bool good) {
        for (std::size_t i = r.begin(); i != r.end() && good; ++i) {
          good = diagonal[i] > 0.0;
          for (int a = 0; a < D; ++a) good = good && lower[a][i] >= 0.0;
        }
        return good;
      },
      [](bool a, bool b) { return a && b; });
  if (!ok) {
    for (std::size_t i = 0; i < n; ++i)
      if (!(diagonal[i] > 0.0)) throw std::invalid_argument(std::string(who) + ": diagonal must be > 0");
    throw std::invalid_argument(std::string(who) + ": face weights must be >= 0");
  }
  return stride;
}

// Next cell coordinate in x-fastest order.
template <int D>
void advance(IVec<D>& c, const IVec<D>& res) {
  for (int a = 0; a < D; ++a) {
    if (++c[a] < res[a]) return;
    c[a] = 0;
  }
}

// Parallel copy (same size) for large arrays.
void copyInto(const std::vector<double>& from, std::vector<double>& to) {
  to.resize(from.size());
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, from.size(), 1 << 15), [&](const tbb::blocked_range<std::size_t>& r) {
    std::copy(from.begin() + r.begin(), from.begin() + r.end(), to.begin() + r.begin());
  });
}

// f(c, i) over the cells [begin, end) of the slowest axis' slices, in x-fastest order.
template <int D, typename F>
void forSlices(const IVec<D>& res, std::size_t sliceSize, int begin, int end, const F& f) {
  IVec<D> c = IVec<D>::Zero();
  c[D - 1] = begin;
  const std::size_t stop = static_cast<std::size_t>(end) * sliceSize;
  for (std::size_t i = static_cast<std::size_t>(begin) * sliceSize; i < stop; advance<D>(c, res), ++i) f(c, i);
}

}  // namespace

template <int D>
GridPoissonQpOperator<D>::GridPoissonQpOperator(const IVec<D>& res, std::array<std::vector<double>, D> lowerWeight,
                                                std::vector<double> diagonal)
    : res_(res),
      stride_(checkStencil<D>("GridPoissonQpOperator", res, lowerWeight, diagonal)),
      lower_(std::move(lowerWeight)),
      diagonal_(std::move(diagonal)) {
  computeNormBound();
}

template <int D>
void GridPoissonQpOperator<D>::assign(const std::array<std::vector<double>, D>& lowerWeight,
                                      const std::vector<double>& diagonal) {
  assign(res_, lowerWeight, diagonal);
}

template <int D>
void GridPoissonQpOperator<D>::assign(const IVec<D>& res, const std::array<std::vector<double>, D>& lowerWeight,
                                      const std::vector<double>& diagonal) {
  stride_ = checkStencil<D>("GridPoissonQpOperator::assign", res, lowerWeight, diagonal);
  res_ = res;
  for (int a = 0; a < D; ++a) copyInto(lowerWeight[a], lower_[a]);
  copyInto(diagonal, diagonal_);
  computeNormBound();
}

template <int D>
void GridPoissonQpOperator<D>::computeNormBound() {
  // Per-slice maxima, combined with max: independent of the split.
  std::size_t slice = 1;
  for (int a = 0; a + 1 < D; ++a) slice *= static_cast<std::size_t>(res_[a]);
  normBound_ = tbb::parallel_reduce(
      tbb::blocked_range<int>(0, res_[D - 1], static_cast<int>(std::max<std::size_t>(1, (1u << 13) / slice))), 0.0,
      [&](const tbb::blocked_range<int>& r, double m) {
        forSlices<D>(res_, slice, r.begin(), r.end(), [&](const IVec<D>& c, std::size_t i) {
          double sum = std::abs(diagonal_[i]);
          for (int a = 0; a < D; ++a) {
            if (c[a] > 0) sum += lower_[a][i];
            if (c[a] + 1 < res_[a]) sum += lower_[a][i + stride_[a]];
          }
          m = std::max(m, sum);
        });
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
}

template <int D>
void GridPoissonQpOperator<D>::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  // Row by row (x rows): whether a row has neighbours across the other axes is the same along
  // it, so each term is one pass over the row with plain indexing. Every entry still takes the
  // diagonal term, then per axis the lower and the upper neighbour, in that order.
  const int nx = res_[0];
  const std::size_t rows = static_cast<std::size_t>(diagonal_.size()) / static_cast<std::size_t>(nx);
  const double* xv = x.data();
  double* yv = y.data();
  auto row = [&](std::size_t r) {
    const std::size_t base = r * static_cast<std::size_t>(nx);
    const double* d = diagonal_.data() + base;
    const double* w0 = lower_[0].data() + base;
    const double* xr = xv + base;
    double* out = yv + base;
    for (int i = 0; i < nx; ++i) out[i] = d[i] * xr[i];
    for (int i = 1; i < nx; ++i) out[i] -= w0[i] * xr[i - 1];
    for (int i = 0; i + 1 < nx; ++i) out[i] -= w0[i + 1] * xr[i + 1];
    std::size_t rest = r;  // the row's coordinates along axes 1..D-1
    for (int a = 1; a < D; ++a) {
      const int c = static_cast<int>(rest % static_cast<std::size_t>(res_[a]));
      rest /= static_cast<std::size_t>(res_[a]);
      const std::size_t st = stride_[a];
      const double* w = lower_[a].data() + base;
      if (c > 0)
        for (int i = 0; i < nx; ++i) out[i] -= w[i] * xr[i - static_cast<std::ptrdiff_t>(st)];
      if (c + 1 < res_[a])
        for (int i = 0; i < nx; ++i) out[i] -= w[i + st] * xr[i + st];
    }
  };
  if (diagonal_.size() < (1u << 15)) {
    for (std::size_t r = 0; r < rows; ++r) row(r);
    return;
  }
  const std::size_t grain = std::max<std::size_t>(1, (1u << 13) / static_cast<std::size_t>(nx));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t k = r.begin(); k != r.end(); ++k) row(k);
  });
}

template <int D>
void GridPoissonQpOperator<D>::diagonal(Eigen::VectorXd& d) const {
  d = Eigen::Map<const Eigen::VectorXd>(diagonal_.data(), size());
}

template <int D>
GridMic0FacePreconditioner<D>::GridMic0FacePreconditioner(const IVec<D>& res,
                                                          std::array<std::vector<double>, D> lowerWeight,
                                                          std::vector<double> diagonal,
                                                          const GridMic0Settings& settings)
    : res_(res),
      stride_(checkStencil<D>("GridMic0FacePreconditioner", res, lowerWeight, diagonal)),
      lower_(std::move(lowerWeight)),
      diagonal_(std::move(diagonal)),
      settings_(settings),
      free_(diagonal_.size(), 1),
      precon_(diagonal_.size(), 0.0),
      q_(diagonal_.size(), 0.0) {
  listFreeCells();
  if (!(settings.tau >= 0.0 && settings.tau <= 1.0) || !(settings.sigma >= 0.0 && settings.sigma <= 1.0))
    throw std::invalid_argument("GridMic0FacePreconditioner: need 0 <= tau <= 1 and 0 <= sigma <= 1");
  factor();
}

template <int D>
void GridMic0FacePreconditioner<D>::setFace(const std::vector<std::uint8_t>& free) {
  if (free.size() != free_.size())
    throw std::invalid_argument("GridMic0FacePreconditioner: face mask has " + std::to_string(free.size()) +
                                " entries, grid has " + std::to_string(free_.size()) + " cells");
  if (!stale_ && std::equal(free.begin(), free.end(), free_.begin(),
                            [](std::uint8_t a, std::uint8_t b) { return (a != 0) == (b != 0); }))
    return;
  for (std::size_t i : freeList_) precon_[i] = 0.0;  // the old face; the new one is factored below
  for (std::size_t i = 0; i < free.size(); ++i) free_[i] = free[i] ? 1 : 0;
  listFreeCells();
  factor();
}

template <int D>
void GridMic0FacePreconditioner<D>::listFreeCells() {
  freeList_.clear();
  neighbours_.clear();
  IVec<D> c = IVec<D>::Zero();
  for (std::size_t i = 0; i < free_.size(); ++i, advance<D>(c, res_)) {
    if (!free_[i]) continue;
    std::uint8_t bits = 0;
    for (int a = 0; a < D; ++a) {
      if (c[a] > 0) bits |= std::uint8_t(1u << a);
      if (c[a] + 1 < res_[a]) bits |= std::uint8_t(1u << (D + a));
    }
    freeList_.push_back(i);
    neighbours_.push_back(bits);
  }
}

template <int D>
void GridMic0FacePreconditioner<D>::assign(const std::array<std::vector<double>, D>& lowerWeight,
                                           const std::vector<double>& diagonal) {
  assign(res_, lowerWeight, diagonal);
}

template <int D>
void GridMic0FacePreconditioner<D>::assign(const IVec<D>& res, const std::array<std::vector<double>, D>& lowerWeight,
                                           const std::vector<double>& diagonal) {
  stride_ = checkStencil<D>("GridMic0FacePreconditioner::assign", res, lowerWeight, diagonal);
  for (int a = 0; a < D; ++a) copyInto(lowerWeight[a], lower_[a]);
  copyInto(diagonal, diagonal_);
  if (res != res_) {  // a new grid: every cell free until the next setFace()
    res_ = res;
    const std::size_t n = diagonal_.size();
    free_.assign(n, 1);
    precon_.assign(n, 0.0);
    q_.assign(n, 0.0);
    listFreeCells();
  }
  stale_ = true;
}

// Bridson's MIC(0) (fluid notes fig. 4.2) of A_FF: for each free cell i in order, with the
// already factored free lower neighbours j = i - e_a, coupling w = w_a(i),
//   e = A_ii - sum_a [ (w precon_j)^2 + tau w (sum_{b != a} w_b(j + e_b) [j + e_b free]) precon_j^2 ],
// precon_i = 1 / sqrt(e), or 1 / sqrt(A_ii) when e < sigma A_ii. Held cells get precon = 0, which
// also zeroes their terms for the neighbours; only the fill-in couplings j -> j + e_b (cells not
// yet factored) need the mask. The tau term puts the dropped fill-in back onto the diagonal, so
// L L^T keeps A_FF's row sums (the "modified" in MIC), which is what damps the smooth error modes.
template <int D>
void GridMic0FacePreconditioner<D>::factor() {
  const double tau = settings_.tau, sigma = settings_.sigma;
  // Held cells keep precon = 0 (setFace() zeroes the old face), so only the free cells, in
  // increasing order, need the sweep.
  for (std::size_t f = 0; f < freeList_.size(); ++f) {
    const std::size_t i = freeList_[f];
    const unsigned bits = neighbours_[f];
    double e = diagonal_[i];
    for (int a = 0; a < D; ++a) {
      if (!(bits & (1u << a))) continue;
      const std::size_t j = i - stride_[a];
      const double pj = precon_[j];
      if (pj == 0.0) continue;
      const double w = lower_[a][i];
      double fill = 0.0;  // couplings of j to its other upper neighbours: the fill-in that (j, i) would create
      for (int b = 0; b < D; ++b) {
        if (b == a || !(bits & (1u << (D + b)))) continue;  // j shares i's coordinate on axes b != a
        const std::size_t k = j + stride_[b];
        if (free_[k]) fill += lower_[b][k];
      }
      e -= (w * pj) * (w * pj) + tau * w * fill * pj * pj;
    }
    if (e < sigma * diagonal_[i]) e = diagonal_[i];
    precon_[i] = 1.0 / std::sqrt(e);
  }
  ++factorizations_;
  stale_ = false;
}

// L(i, i) = 1 / precon_i and L(i, i - e_a) = -w_a(i) precon_{i - e_a}; both vanish off the face,
// so the solves only visit the free cells (in x-fastest order and back), O(|F|) plus clearing z.
template <int D>
void GridMic0FacePreconditioner<D>::apply(const Eigen::VectorXd& g, Eigen::VectorXd& z) {
  if (stale_) factor();
  const double* pc = precon_.data();
  double* q = q_.data();
  // Only the free cells carry values: q on held cells may be stale but is multiplied by their
  // precon = 0, and z is zeroed first so the held neighbours contribute nothing to L^T z = q.
  z.setZero();
  const std::size_t count = freeList_.size();
  for (std::size_t f = 0; f < count; ++f) {  // L q = g
    const std::size_t i = freeList_[f];
    const unsigned bits = neighbours_[f];
    double t = g[i];
    for (int a = 0; a < D; ++a)
      if (bits & (1u << a)) t += lower_[a][i] * pc[i - stride_[a]] * q[i - stride_[a]];
    q[i] = t * pc[i];
  }
  for (std::size_t f = count; f-- > 0;) {  // L^T z = q, reverse order
    const std::size_t i = freeList_[f];
    const unsigned bits = neighbours_[f];
    double t = q[i];
    for (int a = 0; a < D; ++a)
      if (bits & (1u << (D + a))) t += lower_[a][i + stride_[a]] * pc[i] * z[i + stride_[a]];
    z[i] = t * pc[i];
  }
}

template class GridPoissonQpOperator<2>;
template class GridPoissonQpOperator<3>;
template class GridMic0FacePreconditioner<2>;
template class GridMic0FacePreconditioner<3>;

}  // namespace msim::numerics
