#pragma once
// GridSpec<D>: the geometry of a uniform Cartesian grid (origin of its lower corner, cell size dx,
// cells per axis). Every sampled field (cell-centred or face-centred) is laid over one of these.
#include <cmath>
#include <cstddef>
#include <cstdint>

#include "msim/core/vec.hpp"

namespace msim {

template <int D>
struct GridSpec {
  Vec<D> origin = Vec<D>::Zero();  // world position of the lower corner of cell 0 [m]
  double dx = 1.0;                 // cell size [m]
  IVec<D> res = IVec<D>::Ones();   // cells per axis

  GridSpec() = default;
  GridSpec(const Vec<D>& origin_, double dx_, const IVec<D>& res_) : origin(origin_), dx(dx_), res(res_) {}

  std::size_t cellCount() const {
    std::size_t n = 1;
    for (int a = 0; a < D; ++a) n *= static_cast<std::size_t>(res[a]);
    return n;
  }
  Vec<D> extent() const { return res.template cast<double>() * dx; }
  Vec<D> upper() const { return origin + extent(); }
  Vec<D> cellCenter(const IVec<D>& c) const { return origin + (c.template cast<double>().array() + 0.5).matrix() * dx; }
  bool contains(const Vec<D>& x) const {
    for (int a = 0; a < D; ++a)
      if (x[a] < origin[a] || x[a] > origin[a] + res[a] * dx) return false;
    return true;
  }
  // Linear index (x fastest) of the cell holding x, clamped into the grid.
  template <typename Position>
  std::size_t clampedCellIndex(const Position& x) const {
    std::size_t index = 0, stride = 1;
    for (int a = 0; a < D; ++a) {
      const double s = std::floor((double(x[a]) - origin[a]) / dx);
      const int c = s < 0.0 ? 0 : (s >= res[a] ? res[a] - 1 : static_cast<int>(s));
      index += static_cast<std::size_t>(c) * stride;
      stride *= static_cast<std::size_t>(res[a]);
    }
    return index;
  }
  double cellVolume() const {
    double v = 1.0;
    for (int a = 0; a < D; ++a) v *= dx;
    return v;
  }
  bool operator==(const GridSpec&) const = default;
};

}  // namespace msim
