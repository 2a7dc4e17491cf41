#pragma once
// Linear resampling of one regular grid onto another over the same region (a coarse field onto a
// finer grid, or back): per axis the two source samples and the weight are tabulated once, so each
// target sample costs 2^D reads, where sampleLinear would redo the index arithmetic per sample.
// Positions outside the source's samples clamp to its border (as sampleLinear does).
// blockAverage goes the other way: each coarse sample the mean of the fine samples it covers.
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

// coarse(c) = mean of fine(c * ratio + k) over k in [0, block) per axis: with block = ratio on
// every axis, cell averages of a grid `ratio` times finer; with block 1 along a face grid's normal
// axis, the fine faces that tile each coarse face (the coarse flux is their mean). Walks the fine
// grid row by row along axis 0.
template <int D>
void blockAverage(const Grid<float, D>& fine, Grid<float, D>& coarse, int ratio, const IVec<D>& block) {
  const IVec<D> size = coarse.size();
  std::size_t rows = 1, blockRows = 1;
  for (int d = 1; d < D; ++d) {
    rows *= static_cast<std::size_t>(size[d]);
    blockRows *= static_cast<std::size_t>(block[d]);
  }
  int count = 1;
  for (int d = 0; d < D; ++d) count *= block[d];
  const float* data = fine.data().data();
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows, 16), [&](const tbb::blocked_range<std::size_t>& range) {
    std::vector<double> sum(static_cast<std::size_t>(size[0]));
    for (std::size_t row = range.begin(); row != range.end(); ++row) {
      std::fill(sum.begin(), sum.end(), 0.0);
      for (std::size_t k = 0; k < blockRows; ++k) {
        // The fine row: coarse row coordinates times ratio plus this block row's offsets.
        std::ptrdiff_t base = 0;
        std::size_t restRow = row, restK = k;
        for (int d = 1; d < D; ++d) {
          const auto c = static_cast<std::ptrdiff_t>(restRow % static_cast<std::size_t>(size[d]));
          const auto o = static_cast<std::ptrdiff_t>(restK % static_cast<std::size_t>(block[d]));
          restRow /= static_cast<std::size_t>(size[d]);
          restK /= static_cast<std::size_t>(block[d]);
          base += (c * ratio + o) * fine.stride(d);
        }
        const float* line = data + base;
        for (int i = 0; i < size[0]; ++i)
          for (int o = 0; o < block[0]; ++o) sum[static_cast<std::size_t>(i)] += line[i * ratio + o];
      }
      float* out = coarse.data().data() + row * static_cast<std::size_t>(size[0]);
      for (int i = 0; i < size[0]; ++i) out[i] = static_cast<float>(sum[static_cast<std::size_t>(i)] / count);
    }
  });
}

}  // namespace msim
