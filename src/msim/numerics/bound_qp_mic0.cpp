#include "msim/numerics/bound_qp_mic0.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <string>
#include <utility>

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
  for (std::size_t i = 0; i < n; ++i) {
    if (!(diagonal[i] > 0.0)) throw std::invalid_argument(std::string(who) + ": diagonal must be > 0");
    for (int a = 0; a < D; ++a)
      if (!(lower[a][i] >= 0.0)) throw std::invalid_argument(std::string(who) + ": face weights must be >= 0");
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

// Previous cell coordinate in x-fastest order.
template <int D>
void retreat(IVec<D>& c, const IVec<D>& res) {
  for (int a = 0; a < D; ++a) {
    if (--c[a] >= 0) return;
    c[a] = res[a] - 1;
  }
}

}  // namespace

template <int D>
GridPoissonQpOperator<D>::GridPoissonQpOperator(const IVec<D>& res, std::array<std::vector<double>, D> lowerWeight,
                                                std::vector<double> diagonal)
    : res_(res),
      stride_(checkStencil<D>("GridPoissonQpOperator", res, lowerWeight, diagonal)),
      lower_(std::move(lowerWeight)),
      diagonal_(std::move(diagonal)) {
  IVec<D> c = IVec<D>::Zero();
  for (std::size_t i = 0; i < diagonal_.size(); advance<D>(c, res_), ++i) {
    double sum = std::abs(diagonal_[i]);
    for (int a = 0; a < D; ++a) {
      if (c[a] > 0) sum += lower_[a][i];
      if (c[a] + 1 < res_[a]) sum += lower_[a][i + stride_[a]];
    }
    normBound_ = std::max(normBound_, sum);
  }
}

template <int D>
void GridPoissonQpOperator<D>::apply(const Eigen::VectorXd& x, Eigen::VectorXd& y) const {
  IVec<D> c = IVec<D>::Zero();
  for (std::size_t i = 0; i < diagonal_.size(); advance<D>(c, res_), ++i) {
    double s = diagonal_[i] * x[i];
    for (int a = 0; a < D; ++a) {
      if (c[a] > 0) s -= lower_[a][i] * x[i - stride_[a]];
      if (c[a] + 1 < res_[a]) s -= lower_[a][i + stride_[a]] * x[i + stride_[a]];
    }
    y[i] = s;
  }
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
      q_(Eigen::VectorXd::Zero(static_cast<Eigen::Index>(diagonal_.size()))) {
  if (!(settings.tau >= 0.0 && settings.tau <= 1.0) || !(settings.sigma >= 0.0 && settings.sigma <= 1.0))
    throw std::invalid_argument("GridMic0FacePreconditioner: need 0 <= tau <= 1 and 0 <= sigma <= 1");
  factor();
}

template <int D>
void GridMic0FacePreconditioner<D>::setFace(const std::vector<std::uint8_t>& free) {
  if (free.size() != free_.size())
    throw std::invalid_argument("GridMic0FacePreconditioner: face mask has " + std::to_string(free.size()) +
                                " entries, grid has " + std::to_string(free_.size()) + " cells");
  bool same = true;
  for (std::size_t i = 0; i < free.size() && same; ++i) same = (free[i] != 0) == (free_[i] != 0);
  if (same) return;
  for (std::size_t i = 0; i < free.size(); ++i) free_[i] = free[i] ? 1 : 0;
  factor();
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
  IVec<D> c = IVec<D>::Zero();
  for (std::size_t i = 0; i < diagonal_.size(); advance<D>(c, res_), ++i) {
    if (!free_[i]) {
      precon_[i] = 0.0;
      continue;
    }
    double e = diagonal_[i];
    for (int a = 0; a < D; ++a) {
      if (c[a] == 0) continue;
      const std::size_t j = i - stride_[a];
      const double pj = precon_[j];
      if (pj == 0.0) continue;
      const double w = lower_[a][i];
      double fill = 0.0;  // couplings of j to its other upper neighbours: the fill-in that (j, i) would create
      for (int b = 0; b < D; ++b) {
        if (b == a || c[b] + 1 >= res_[b]) continue;  // j shares i's coordinate on axes b != a
        const std::size_t k = j + stride_[b];
        if (free_[k]) fill += lower_[b][k];
      }
      e -= (w * pj) * (w * pj) + tau * w * fill * pj * pj;
    }
    if (e < sigma * diagonal_[i]) e = diagonal_[i];
    precon_[i] = 1.0 / std::sqrt(e);
  }
  ++factorizations_;
}

// L(i, i) = 1 / precon_i and L(i, i - e_a) = -w_a(i) precon_{i - e_a}; both vanish off the face,
// so the solves need no mask: q and z come out 0 on held cells.
template <int D>
void GridMic0FacePreconditioner<D>::apply(const Eigen::VectorXd& g, Eigen::VectorXd& z) {
  const std::size_t n = diagonal_.size();
  const double* pc = precon_.data();
  double* q = q_.data();
  IVec<D> c = IVec<D>::Zero();
  for (std::size_t i = 0; i < n; advance<D>(c, res_), ++i) {  // L q = g
    double t = g[i];
    for (int a = 0; a < D; ++a)
      if (c[a] > 0) t += lower_[a][i] * pc[i - stride_[a]] * q[i - stride_[a]];
    q[i] = t * pc[i];
  }
  c = res_ - IVec<D>::Ones();
  for (std::size_t i = n; i-- > 0; retreat<D>(c, res_)) {  // L^T z = q, reverse order
    double t = q[i];
    for (int a = 0; a < D; ++a)
      if (c[a] + 1 < res_[a]) t += lower_[a][i + stride_[a]] * pc[i] * z[i + stride_[a]];
    z[i] = t * pc[i];
  }
}

template class GridPoissonQpOperator<2>;
template class GridPoissonQpOperator<3>;
template class GridMic0FacePreconditioner<2>;
template class GridMic0FacePreconditioner<3>;

}  // namespace msim::numerics
