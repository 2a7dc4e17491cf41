#pragma once
// Parallel loops over grids and index ranges on oneTBB. Loops over a grid split the slowest axis
// so each task walks contiguous memory. Reductions go through fixed-size blocks combined in a fixed
// order, so a sum is the same whatever the thread count (deterministic reruns).
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/grid.hpp"

namespace msim {

// f(i) for i in [begin, end).
template <typename F>
void parallelFor(std::size_t begin, std::size_t end, F&& f, std::size_t grain = 1024) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(begin, end, grain), [&](const tbb::blocked_range<std::size_t>& r) {
    for (std::size_t i = r.begin(); i != r.end(); ++i) f(i);
  });
}

// f(coord, linear index) for every sample of an index box of the given size (x fastest).
template <int D, typename F>
void parallelForCells(const IVec<D>& size, F&& f) {
  const int outer = size[D - 1];
  tbb::parallel_for(tbb::blocked_range<int>(0, outer, 1), [&](const tbb::blocked_range<int>& r) {
    IVec<D> c = IVec<D>::Zero();
    for (int k = r.begin(); k != r.end(); ++k) {
      c[D - 1] = k;
      if constexpr (D == 2) {
        std::size_t lin = static_cast<std::size_t>(k) * size[0];
        for (int i = 0; i < size[0]; ++i, ++lin) {
          c[0] = i;
          f(c, lin);
        }
      } else {
        for (int j = 0; j < size[1]; ++j) {
          c[1] = j;
          std::size_t lin = (static_cast<std::size_t>(k) * size[1] + j) * size[0];
          for (int i = 0; i < size[0]; ++i, ++lin) {
            c[0] = i;
            f(c, lin);
          }
        }
      }
    }
  });
}

template <typename T, int D, typename F>
void parallelForCells(const Grid<T, D>& g, F&& f) {
  parallelForCells<D>(g.size(), std::forward<F>(f));
}

// Deterministic parallel sum of f(i) over [0, n) in double precision: the range is split by
// halving down to blocks of at most 4096 and the partial sums are combined along that tree, which
// depends on n alone, so a sum is the same whatever the thread count. Nothing is allocated (conjugate
// gradients call it every iteration).
template <typename F>
double parallelSum(std::size_t n, F&& f) {
  constexpr std::size_t kBlock = 4096;
  return tbb::parallel_deterministic_reduce(
      tbb::blocked_range<std::size_t>(0, n, kBlock), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double s) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) s += f(i);
        return s;
      },
      [](double a, double b) { return a + b; });
}

// Parallel max of f(i) over [0, n) (0 for an empty range; f is expected to be >= 0). The max does
// not depend on the order of combination, so the plain parallel reduction is deterministic.
template <typename F>
double parallelMax(std::size_t n, F&& f) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), 0.0,
      [&](const tbb::blocked_range<std::size_t>& r, double m) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) m = std::max(m, static_cast<double>(f(i)));
        return m;
      },
      [](double a, double b) { return std::max(a, b); });
}

// Whether every value is finite (a solver's blow-up check), in parallel.
inline bool allFinite(const std::vector<float>& v) {
  return parallelMax(v.size(), [&](std::size_t i) { return std::isfinite(v[i]) ? 0.0 : 1.0; }) == 0.0;
}

}  // namespace msim
