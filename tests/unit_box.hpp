#pragma once
// The unit square or cube in n cells per side, the grid of many tests.
#include "msim/core/grid.hpp"

namespace msim::test {

template <int D>
GridSpec<D> unitBox(int n) {
  return GridSpec<D>(Vec<D>::Zero(), 1.0 / n, IVec<D>::Constant(n));
}

}  // namespace msim::test
