#pragma once
// StencilRow<D>: one x-row of the face-weighted Poisson stencil, as raw pointers, so the kernels
// of PoissonMatrix and the MIC(0) preconditioner share one boundary treatment. Neighbours beyond
// the domain point at a row of zeros (ghost value 0), which is exactly the Dirichlet condition on
// open sides; on solid walls the face weight is 0, so the ghost value does not matter either way.
#include <algorithm>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/vec.hpp"

namespace msim::numerics {

template <int D>
struct StencilRow {
  std::size_t base = 0;  // linear index of the row's first cell
  int nx = 0;
  IVec<D> coord = IVec<D>::Zero();  // coordinates of the first cell
  const float* w0 = nullptr;        // lower x-face weights of the row
  const float* v = nullptr;         // the row of the vector the stencil reads
  const float* wl[D] = {};          // per axis a >= 1: lower-face weight, lower neighbour,
  const float* vl[D] = {};          //   upper-face weight (the upper cell's lower face),
  const float* wu[D] = {};          //   upper neighbour
  const float* vu[D] = {};

  // sum over faces of w_f v_nb(f) for a cell with both x neighbours inside the row.
  float interior(int i) const {
    float s = w0[i] * v[i - 1] + w0[i + 1] * v[i + 1];
    for (int a = 1; a < D; ++a) s += wl[a][i] * vl[a][i] + wu[a][i] * vu[a][i];
    return s;
  }
  float any(int i) const {
    if (i > 0 && i + 1 < nx) return interior(i);
    float s = 0.0f;
    if (i > 0) s += w0[i] * v[i - 1];
    if (i + 1 < nx) s += w0[i + 1] * v[i + 1];
    for (int a = 1; a < D; ++a) s += wl[a][i] * vl[a][i] + wu[a][i] * vu[a][i];
    return s;
  }
};

// The row `row` (rows are numbered x-row by x-row, y fastest) of a grid with lower-face weights
// `lower`, reading vector v; `zero` is a row of zeros at least res[0] long.
template <int D>
StencilRow<D> makeStencilRow(const IVec<D>& res, const std::size_t* stride, const std::vector<float>* lower,
                             const float* v, const float* zero, std::size_t row) {
  StencilRow<D> s;
  s.nx = res[0];
  s.base = row * static_cast<std::size_t>(res[0]);
  std::size_t rest = row;
  for (int a = 1; a < D; ++a) {
    s.coord[a] = static_cast<int>(rest % static_cast<std::size_t>(res[a]));
    rest /= static_cast<std::size_t>(res[a]);
  }
  s.w0 = lower[0].data() + s.base;
  s.v = v + s.base;
  for (int a = 1; a < D; ++a) {
    const bool hasLower = s.coord[a] > 0, hasUpper = s.coord[a] + 1 < res[a];
    s.wl[a] = lower[a].data() + s.base;
    s.vl[a] = hasLower ? v + s.base - stride[a] : zero;
    s.wu[a] = hasUpper ? lower[a].data() + s.base + stride[a] : zero;
    s.vu[a] = hasUpper ? v + s.base + stride[a] : zero;
  }
  return s;
}

// f(row) for every x-row of a grid of size res, in parallel (rows of one task are contiguous).
template <int D, typename F>
void parallelForRows(const IVec<D>& res, F&& f) {
  std::size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= static_cast<std::size_t>(res[a]);
  const std::size_t grain = std::max<std::size_t>(1, 4096 / static_cast<std::size_t>(res[0]));
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t row = r.begin(); row != r.end(); ++row) f(row);
  });
}

}  // namespace msim::numerics
