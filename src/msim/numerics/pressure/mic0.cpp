#include "msim/numerics/pressure/mic0.hpp"

#include <cmath>


namespace msim::numerics {

namespace {

template <int D>
std::size_t rowCount(const IVec<D>& res) {
  std::size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= static_cast<std::size_t>(res[a]);
  return rows;
}

}  // namespace

template <int D>
Mic0Preconditioner<D>::Mic0Preconditioner(const PoissonMatrix<D>& matrix, const Mic0Settings& settings)
    : matrix_(&matrix), precon_(matrix.size(), 0.0f), q_(matrix.size(), 0.0f) {
  const IVec<D>& res = matrix.res();
  const auto& diag = matrix.diag();
  const double tau = settings.tau, sigma = settings.sigma;
  // Off-diagonal A(i, i + e_a) = -w where w is the lower-face weight of i + e_a; it exists when
  // i + e_a is inside the grid.
  auto upperWeight = [&](std::size_t i, const IVec<D>& c, int a) -> double {
    return c[a] + 1 < res[a] ? matrix.lowerWeight(a)[i + matrix.stride(a)] : 0.0;
  };
  const Grid<float, D> layout(GridSpec<D>(Vec<D>::Zero(), 1.0, res));
  for (std::size_t i = 0; i < matrix.size(); ++i) {
    if (diag[i] <= 0.0f) continue;
    const IVec<D> c = layout.coord(i);
    double e = diag[i];
    for (int a = 0; a < D; ++a) {
      if (c[a] == 0) continue;
      const std::size_t j = i - matrix.stride(a);
      const double w = matrix.lowerWeight(a)[i];
      const double pj = precon_[j];
      e -= (w * pj) * (w * pj);
      IVec<D> cj = c;
      cj[a] -= 1;
      double otherCouplings = 0.0;  // fill-in that L would create between j's other upper neighbours and i
      for (int b = 0; b < D; ++b)
        if (b != a) otherCouplings += upperWeight(j, cj, b);
      e -= tau * w * otherCouplings * pj * pj;
    }
    if (e < sigma * diag[i]) e = diag[i];
    precon_[i] = static_cast<float>(1.0 / std::sqrt(e));
  }
}

template <int D>
void Mic0Preconditioner<D>::apply(const std::vector<float>& r, std::vector<float>& z) {
  const PoissonMatrix<D>& A = *matrix_;
  const IVec<D>& res = A.res();
  const int nx = res[0];
  const float* pc = precon_.data();
  const float* w[D];
  std::size_t st[D];
  for (int a = 0; a < D; ++a) {
    w[a] = A.lowerWeight(a).data();
    st[a] = A.stride(a);
  }
  const std::size_t rows = rowCount<D>(res);
  auto rowCoord = [&](std::size_t row) {
    IVec<D> c = IVec<D>::Zero();
    for (int a = 1; a < D; ++a) {
      c[a] = static_cast<int>(row % static_cast<std::size_t>(res[a]));
      row /= static_cast<std::size_t>(res[a]);
    }
    return c;
  };
  // Forward substitution L q = r with L(i, i - e_a) = -w_a(i) precon(i - e_a), L(i, i) = 1 / precon(i).
  float* q = q_.data();
  for (std::size_t row = 0; row < rows; ++row) {
    const IVec<D> c = rowCoord(row);
    const std::size_t base = row * static_cast<std::size_t>(nx);
    for (int i = 0; i < nx; ++i) {
      const std::size_t k = base + i;
      float t = r[k];
      if (i > 0) t += w[0][k] * pc[k - 1] * q[k - 1];
      for (int a = 1; a < D; ++a)
        if (c[a] > 0) t += w[a][k] * pc[k - st[a]] * q[k - st[a]];
      q[k] = t * pc[k];
    }
  }
  // Back substitution L^T z = q, in reverse order.
  float* out = z.data();
  for (std::size_t row = rows; row-- > 0;) {
    const IVec<D> c = rowCoord(row);
    const std::size_t base = row * static_cast<std::size_t>(nx);
    for (int i = nx - 1; i >= 0; --i) {
      const std::size_t k = base + i;
      float t = q[k];
      if (i + 1 < nx) t += w[0][k + 1] * pc[k] * out[k + 1];
      for (int a = 1; a < D; ++a)
        if (c[a] + 1 < res[a]) t += w[a][k + st[a]] * pc[k] * out[k + st[a]];
      out[k] = t * pc[k];
    }
  }
}

template class Mic0Preconditioner<2>;
template class Mic0Preconditioner<3>;

}  // namespace msim::numerics
