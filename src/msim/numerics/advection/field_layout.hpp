#pragma once
// FieldLayout<D>: where the samples of one gridded field sit and what lies beyond the domain on
// each axis, so the advection building blocks can address neighbours and interpolate on a
// cell-centred grid and on every MAC face grid with the same code.
//
// Periodic axes wrap with the period of the domain (spec.res cells): a face grid along its own
// axis has res+1 samples whose last one is the same physical face as the first. Clamped axes
// extend the border samples outwards (zero gradient), as msim/core/interpolation.hpp does.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "msim/core/block_placement.hpp"
#include "msim/core/grid.hpp"

namespace msim::numerics {

enum class AxisBoundary { Clamped, Periodic };

template <int D>
using AxisBoundaries = std::array<AxisBoundary, D>;

template <int D>
AxisBoundaries<D> allClamped() {
  AxisBoundaries<D> b;
  b.fill(AxisBoundary::Clamped);
  return b;
}

template <int D>
AxisBoundaries<D> allPeriodic() {
  AxisBoundaries<D> b;
  b.fill(AxisBoundary::Periodic);
  return b;
}

// The 2^D samples a D-linear interpolation reads, with their weights.
template <int D>
struct InterpolationStencil {
  static constexpr int kCorners = 1 << D;
  std::size_t index[kCorners];
  double weight[kCorners];
};

template <int D>
struct FieldLayout {
  IVec<D> size;
  std::ptrdiff_t stride[D];
  Vec<D> origin;  // world position of sample 0
  double dx;
  int period[D];  // samples per period on periodic axes (= spec.res)
  bool periodic[D];
  int first[D];       // global index of sample 0 (0 unless the grid is a block of a larger one)
  int globalSize[D];  // samples per axis of the global field (= size unless a block)

  template <typename T>
  static FieldLayout of(const Grid<T, D>& g, const AxisBoundaries<D>& boundaries,
                        const BlockPlacement<D>& placement = {}) {
    FieldLayout l;
    for (int a = 0; a < D; ++a) {
      // A face grid has one sample more than cells along its axis, locally and globally.
      const int extra = g.size()[a] - g.spec().res[a];
      l.first[a] = placement.whole() ? 0 : placement.cellOrigin[a];
      l.globalSize[a] = placement.whole() ? g.size()[a] : placement.globalRes[a] + extra;
    }
    l.size = g.size();
    l.origin = g.position(IVec<D>::Zero());
    l.dx = g.spec().dx;
    for (int a = 0; a < D; ++a) {
      l.stride[a] = g.stride(a);
      l.period[a] = g.spec().res[a];
      l.periodic[a] = boundaries[a] == AxisBoundary::Periodic;
    }
    return l;
  }

  Vec<D> position(const IVec<D>& c) const { return origin + c.template cast<double>() * dx; }

  // Index along `axis` of the sample `delta` steps away from sample i (wrapped or clamped).
  int neighbour(int axis, int i, int delta) const {
    int j = i + delta;
    if (periodic[axis]) {
      j %= period[axis];
      return j < 0 ? j + period[axis] : j;
    }
    return j < 0 ? 0 : (j >= size[axis] ? size[axis] - 1 : j);
  }

  // Stencil of the D-linear interpolation at world position x.
  InterpolationStencil<D> stencil(const Vec<D>& x) const {
    std::ptrdiff_t lo[D], hi[D];
    double t[D];
    for (int a = 0; a < D; ++a) {
      double s = (x[a] - origin[a]) / dx;
      if (!std::isfinite(s)) s = 0.0;  // a bad position must never index outside the grid
      const int n = size[a];
      int i0;
      if (n < 2) {
        i0 = 0;
        t[a] = 0.0;
      } else if (periodic[a]) {
        const double f = std::floor(s);
        t[a] = s - f;
        i0 = neighbour(a, static_cast<int>(std::fmod(f, static_cast<double>(period[a]))), 0);
      } else {
        s = s > 0.0 ? (s < n - 1.0 ? s : n - 1.0) : 0.0;
        i0 = std::min(static_cast<int>(s), n - 2);
        t[a] = s - i0;
      }
      // On a periodic cell axis sample `period` wraps to 0; on a face axis it is a real sample.
      const int i1 = n < 2 ? 0 : (i0 + 1 < n ? i0 + 1 : 0);
      lo[a] = i0 * stride[a];
      hi[a] = i1 * stride[a];
    }
    InterpolationStencil<D> st;
    for (int k = 0; k < InterpolationStencil<D>::kCorners; ++k) {
      std::ptrdiff_t offset = 0;
      double w = 1.0;
      for (int a = 0; a < D; ++a) {
        const bool upper = (k >> a) & 1;
        offset += upper ? hi[a] : lo[a];
        w *= upper ? t[a] : 1.0 - t[a];
      }
      st.index[k] = static_cast<std::size_t>(offset);
      st.weight[k] = w;
    }
    return st;
  }
};

// D-linear interpolation of the samples `data` laid out as `layout` at world position x.
template <typename T, int D>
double interpolate(const FieldLayout<D>& layout, const T* data, const Vec<D>& x) {
  const InterpolationStencil<D> st = layout.stencil(x);
  double v = 0.0;
  for (int k = 0; k < InterpolationStencil<D>::kCorners; ++k) v += st.weight[k] * data[st.index[k]];
  return v;
}

}  // namespace msim::numerics
