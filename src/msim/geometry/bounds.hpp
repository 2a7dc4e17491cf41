#pragma once
// Axis-aligned bounding box of a shape; unbounded shapes (a half-space) use infinite corners.
#include <limits>

#include "msim/core/vec.hpp"

namespace msim::geometry {

template <int D>
struct Bounds {
  Vec<D> min;
  Vec<D> max;

  static Bounds infinite() {
    constexpr double inf = std::numeric_limits<double>::infinity();
    return {Vec<D>::Constant(-inf), Vec<D>::Constant(inf)};
  }
  bool contains(const Vec<D>& x) const { return (x.array() >= min.array()).all() && (x.array() <= max.array()).all(); }
};

using Bounds2 = Bounds<2>;
using Bounds3 = Bounds<3>;

}  // namespace msim::geometry
