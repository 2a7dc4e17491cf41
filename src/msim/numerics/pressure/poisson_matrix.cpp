#include "msim/numerics/pressure/poisson_matrix.hpp"

#include <algorithm>

#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"
#include "msim/numerics/pressure/stencil_row.hpp"

namespace msim::numerics {

template <int D>
PoissonMatrix<D>::PoissonMatrix(const MacGrid<D>& faceWeight) : PoissonMatrix(faceWeight, {}) {}

template <int D>
PoissonMatrix<D>::PoissonMatrix(const MacGrid<D>& faceWeight, const std::vector<float>& dirichletDiagonal)
    : res_(faceWeight.spec().res) {
  const std::size_t n = faceWeight.spec().cellCount();
  std::size_t s = 1;
  for (int a = 0; a < D; ++a) {
    stride_[a] = s;
    s *= static_cast<std::size_t>(res_[a]);
    lower_[a].assign(n, 0.0f);
  }
  diag_.assign(n, 0.0f);
  invDiag_.assign(n, 0.0f);
  zeroRow_.assign(static_cast<std::size_t>(res_[0]), 0.0f);
  parallelForCells<D>(res_, [&](const IVec<D>& c, std::size_t lin) {
    float d = 0.0f;
    for (int a = 0; a < D; ++a) {
      const auto& w = faceWeight.component(a);
      IVec<D> up = c;
      up[a] += 1;
      lower_[a][lin] = w(c);
      d += w(c) + w(up);
    }
    if (!dirichletDiagonal.empty()) d += dirichletDiagonal[lin];
    diag_[lin] = d;
    invDiag_[lin] = d > 0.0f ? 1.0f / d : 0.0f;
  });
}

template <int D>
void PoissonMatrix<D>::apply(const std::vector<float>& x, std::vector<float>& y) const {
  parallelForRows<D>(res_, [&](std::size_t row) {
    const auto s = makeStencilRow<D>(res_, stride_.data(), lower_.data(), x.data(), zeroRow_.data(), row);
    const float* d = diag_.data() + s.base;
    float* out = y.data() + s.base;
    out[0] = d[0] * s.v[0] - s.any(0);
    for (int i = 1; i + 1 < s.nx; ++i) out[i] = d[i] * s.v[i] - s.interior(i);
    if (s.nx > 1) out[s.nx - 1] = d[s.nx - 1] * s.v[s.nx - 1] - s.any(s.nx - 1);
  });
}

template <int D>
void PoissonMatrix<D>::residual(const std::vector<float>& b, const std::vector<float>& x, std::vector<float>& r) const {
  parallelForRows<D>(res_, [&](std::size_t row) {
    const auto s = makeStencilRow<D>(res_, stride_.data(), lower_.data(), x.data(), zeroRow_.data(), row);
    const float* d = diag_.data() + s.base;
    const float* rhs = b.data() + s.base;
    float* out = r.data() + s.base;
    out[0] = rhs[0] - d[0] * s.v[0] + s.any(0);
    for (int i = 1; i + 1 < s.nx; ++i) out[i] = rhs[i] - d[i] * s.v[i] + s.interior(i);
    if (s.nx > 1) out[s.nx - 1] = rhs[s.nx - 1] - d[s.nx - 1] * s.v[s.nx - 1] + s.any(s.nx - 1);
  });
}

template <int D>
void PoissonMatrix<D>::relaxRow(const std::vector<float>& b, std::vector<float>& x, int colour, std::size_t row) const {
  const auto s = makeStencilRow<D>(res_, stride_.data(), lower_.data(), x.data(), zeroRow_.data(), row);
  int parity = colour;
  for (int a = 1; a < D; ++a) parity += s.coord[a];
  const float* inv = invDiag_.data() + s.base;
  const float* rhs = b.data() + s.base;
  float* out = x.data() + s.base;
  // Excluded cells have invDiag 0, so they stay at 0 without a branch. The row's end cells are
  // peeled off so the strided interior loop has no boundary tests.
  const int first = parity & 1, last = s.nx - 1;
  if (first == 0) out[0] = inv[0] * (rhs[0] + s.any(0));
  for (int i = first == 0 ? 2 : 1; i < last; i += 2) out[i] = inv[i] * (rhs[i] + s.interior(i));
  if (last > 0 && (last & 1) == first) out[last] = inv[last] * (rhs[last] + s.any(last));
}

template <int D>
void PoissonMatrix<D>::gaussSeidel(const std::vector<float>& b, std::vector<float>& x, int colour) const {
  parallelForRows<D>(res_, [&](std::size_t row) { relaxRow(b, x, colour, row); });
}

template <int D>
void PoissonMatrix<D>::relaxCells(const std::vector<float>& b, std::vector<float>& x,
                                  const std::vector<std::size_t>& cells) const {
  parallelFor(0, cells.size(), [&](std::size_t k) {
    const std::size_t i = cells[k];
    std::size_t rest = i;
    float sum = 0.0f;
    for (int a = 0; a < D; ++a) {
      const int c = static_cast<int>(rest % static_cast<std::size_t>(res_[a]));
      rest /= static_cast<std::size_t>(res_[a]);
      // Beyond the domain the ghost value is 0 (open) or the weight is 0 (wall): no term.
      if (c > 0) sum += lower_[a][i] * x[i - stride_[a]];
      if (c + 1 < res_[a]) sum += lower_[a][i + stride_[a]] * x[i + stride_[a]];
    }
    x[i] = invDiag_[i] * (b[i] + sum);
  }, 256);
}

// Same updates in the same order per cell as gaussSeidel(first) then gaussSeidel(1 - first), but
// in one pass over memory: in each slab of planes (last axis), plane p gets its first colour and
// then plane p - 1 its second, whose neighbours are all final by then. A slab's first and last
// planes take their second colour only after every slab is through (their neighbours in the next
// slabs must still see the old values before that). The half sweeps are memory bound, so reading
// the arrays once instead of twice is the gain.
template <int D>
void PoissonMatrix<D>::gaussSeidelPair(const std::vector<float>& b, std::vector<float>& x, int first) const {
  constexpr int kSlab = 16;
  const int planes = res_[D - 1];
  std::size_t rowsPerPlane = 1;
  for (int a = 1; a + 1 < D; ++a) rowsPerPlane *= static_cast<std::size_t>(res_[a]);
  auto relaxPlane = [&](int plane, int colour) {
    for (std::size_t r = 0; r < rowsPerPlane; ++r) relaxRow(b, x, colour, plane * rowsPerPlane + r);
  };
  const int slabs = (planes + kSlab - 1) / kSlab;
  tbb::parallel_for(0, slabs, [&](int slab) {
    const int p0 = slab * kSlab, p1 = std::min(planes, p0 + kSlab);
    for (int p = p0; p < p1; ++p) {
      relaxPlane(p, first);
      if (p - 1 > p0) relaxPlane(p - 1, 1 - first);
    }
  });
  tbb::parallel_for(0, slabs, [&](int slab) {
    const int p0 = slab * kSlab, p1 = std::min(planes, p0 + kSlab);
    relaxPlane(p0, 1 - first);
    if (p1 - 1 > p0) relaxPlane(p1 - 1, 1 - first);
  });
}

template class PoissonMatrix<2>;
template class PoissonMatrix<3>;

}  // namespace msim::numerics
