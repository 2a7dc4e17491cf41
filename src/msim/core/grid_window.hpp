#pragma once
// A window of a grid: a smaller grid with the same spacing and sample offset whose sample c is the
// big grid's sample lo + c. forEachWindowRow pairs their rows along axis 0 (in parallel), so
// copying in and out or adding one to the other are plain loops over contiguous memory. Solvers
// that only need part of a large grid (the fine smoke of procedural turbulence) work on a window.
#include <cstddef>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/grid.hpp"

namespace msim {

// f(bigRow, windowRow, length) for every row of `window`; Big and Window are Grid<T, D> or
// const Grid<T, D>. The window must fit inside the big grid at lo.
template <int D, typename Big, typename Window, typename F>
void forEachWindowRow(Big& big, const IVec<D>& lo, Window& window, F&& f) {
  const IVec<D>& size = window.size();
  std::size_t rows = 1;
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(size[d]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 16), [&](const tbb::blocked_range<std::size_t>& range) {
    for (std::size_t row = range.begin(); row != range.end(); ++row) {
      std::ptrdiff_t bigOffset = lo[0];
      std::size_t rest = row;
      for (int d = 1; d < D; ++d) {
        const auto c = static_cast<std::ptrdiff_t>(rest % static_cast<std::size_t>(size[d]));
        rest /= static_cast<std::size_t>(size[d]);
        bigOffset += (lo[d] + c) * big.stride(d);
      }
      f(big.data().data() + bigOffset, window.data().data() + row * static_cast<std::size_t>(size[0]),
        static_cast<std::size_t>(size[0]));
    }
  });
}

}  // namespace msim
