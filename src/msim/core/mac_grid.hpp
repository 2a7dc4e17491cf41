#pragma once
// MacGrid<D>: staggered (marker-and-cell) velocity. Component a lives on the faces normal to
// axis a: res[a]+1 samples along a, res[b] along the others, offset 0 along a and 0.5 elsewhere.
#include <algorithm>
#include <array>
#include <cmath>

#include "msim/core/grid.hpp"
#include "msim/core/parallel.hpp"

namespace msim {

template <int D>
class MacGrid {
 public:
  MacGrid() = default;
  explicit MacGrid(const GridSpec<D>& spec, float value = 0.0f) : spec_(spec) {
    for (int a = 0; a < D; ++a) {
      IVec<D> n = spec.res;
      n[a] += 1;
      Vec<D> off = Vec<D>::Constant(0.5);
      off[a] = 0.0;
      faces_[a] = Grid<float, D>(spec, n, off, value);
    }
  }
  const GridSpec<D>& spec() const { return spec_; }
  Grid<float, D>& component(int a) { return faces_[a]; }
  const Grid<float, D>& component(int a) const { return faces_[a]; }
  void fill(float v) {
    for (auto& f : faces_) f.fill(v);
  }

 private:
  GridSpec<D> spec_;
  std::array<Grid<float, D>, D> faces_;
};

// Largest |u| over every face of every component (the CFL speed of a MAC velocity).
template <int D>
double maxFaceSpeed(const MacGrid<D>& velocity) {
  double speed = 0.0;
  for (int a = 0; a < D; ++a) {
    const Grid<float, D>& u = velocity.component(a);
    speed = std::max(speed, parallelMax(u.count(), [&](std::size_t i) { return std::abs(u[i]); }));
  }
  return speed;
}

}  // namespace msim
