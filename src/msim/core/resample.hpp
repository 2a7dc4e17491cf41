#pragma once
// Linear resampling of one regular grid onto another over the same region (a coarse field onto a
// finer grid, or back): per axis the two source samples and the weight are tabulated once, so each
// target sample costs 2^D reads, where sampleLinear would redo the index arithmetic per sample.
// Positions outside the source's samples clamp to its border (as sampleLinear does).
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/parallel.hpp"

namespace msim {

template <int D>
void resampleLinear(const Grid<float, D>& from, Grid<float, D>& to) {
  struct Tap {
    std::size_t lower, upper;
    float fraction;
  };
  std::array<std::vector<Tap>, D> taps;
  for (int d = 0; d < D; ++d) {
    const int n = from.size()[d];
    taps[d].resize(static_cast<std::size_t>(to.size()[d]));
    IVec<D> c = IVec<D>::Zero();
    for (int i = 0; i < to.size()[d]; ++i) {
      c[d] = i;
      const double s = std::clamp(from.toSampleSpace(to.position(c))[d], 0.0, double(n - 1));
      const int lo = std::min(static_cast<int>(s), std::max(n - 2, 0));
      const int hi = std::min(lo + 1, n - 1);
      const auto stride = static_cast<std::size_t>(from.stride(d));
      taps[d][i] = Tap{static_cast<std::size_t>(lo) * stride, static_cast<std::size_t>(hi) * stride,
                       static_cast<float>(s - lo)};
    }
  }
  const float* data = from.data().data();
  parallelForCells<D>(to.size(), [&](const IVec<D>& c, std::size_t lin) {
    float sum = 0.0f;
    for (int corner = 0; corner < (1 << D); ++corner) {
      std::size_t index = 0;
      float w = 1.0f;
      for (int d = 0; d < D; ++d) {
        const Tap& t = taps[d][static_cast<std::size_t>(c[d])];
        const bool up = (corner >> d) & 1;
        index += up ? t.upper : t.lower;
        w *= up ? t.fraction : 1.0f - t.fraction;
      }
      sum += w * data[index];
    }
    to[lin] = sum;
  });
}

}  // namespace msim
