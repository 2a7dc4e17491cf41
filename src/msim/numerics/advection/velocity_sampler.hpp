#pragma once
// VelocitySampler<D>: the MAC velocity at any world position, each component interpolated
// D-linearly on its own face grid with the advector's boundary handling (so a periodic domain
// sees a periodic velocity). `scale` flips or scales the field: the backward (A^R) steps of
// BFECC and MacCormack run the same building block with scale = -1 (Selle ch. 2.4).
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/field_layout.hpp"

namespace msim::numerics {

template <int D>
struct VelocitySampler {
  FieldLayout<D> layout[D];
  const float* data[D];
  double scale = 1.0;

  VelocitySampler(const MacGrid<D>& velocity, const AxisBoundaries<D>& boundaries, double scale_ = 1.0)
      : scale(scale_) {
    for (int a = 0; a < D; ++a) {
      layout[a] = FieldLayout<D>::of(velocity.component(a), boundaries);
      data[a] = velocity.component(a).data().data();
    }
  }

  Vec<D> operator()(const Vec<D>& x) const {
    Vec<D> u;
    for (int a = 0; a < D; ++a) u[a] = scale * interpolate(layout[a], data[a], x);
    return u;
  }
};

}  // namespace msim::numerics
