#pragma once
// Linear resampling of one regular grid onto another over the same region (a coarse field onto a
// finer grid, or back): per axis the two source samples and the weight are tabulated once, so each
// target sample costs 2^D reads, where sampleLinear would redo the index arithmetic per sample.
// Positions outside the source's samples clamp to its border (as sampleLinear does).
#include <array>
#include <cstddef>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/linear_taps.hpp"
#include "msim/core/parallel.hpp"

namespace msim {

template <int D>
void resampleLinear(const Grid<float, D>& from, Grid<float, D>& to) {
  std::array<std::vector<LinearTap>, D> taps;
  for (int d = 0; d < D; ++d) {
    taps[d].resize(static_cast<std::size_t>(to.size()[d]));
    IVec<D> c = IVec<D>::Zero();
    for (int i = 0; i < to.size()[d]; ++i) {
      c[d] = i;
      taps[d][i] = clampedTap(from.toSampleSpace(to.position(c))[d], from.size()[d], static_cast<std::size_t>(from.stride(d)));
    }
  }
  const float* data = from.data().data();
  parallelForCells<D>(to.size(), [&](const IVec<D>& c, std::size_t lin) {
    std::array<LinearTap, D> at;
    for (int d = 0; d < D; ++d) at[d] = taps[d][static_cast<std::size_t>(c[d])];
    to[lin] = blendCorners<D>(at, data);
  });
}

}  // namespace msim
