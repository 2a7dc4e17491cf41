#pragma once
// A cell-centred field sampled from a function of the position (a level set of a test's body of
// liquid, a manufactured solution): value(x) at every cell centre of spec.
#include "msim/core/grid.hpp"

namespace msim::test {

template <int D, typename F>
Grid<float, D> cellField(const GridSpec<D>& spec, F&& value) {
  Grid<float, D> field(spec);
  for (std::size_t i = 0; i < field.count(); ++i) field[i] = static_cast<float>(value(field.position(field.coord(i))));
  return field;
}

}  // namespace msim::test
