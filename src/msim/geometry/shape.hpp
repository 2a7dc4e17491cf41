#pragma once
// Shape<D>: a solid described by its signed distance (negative inside, zero on the surface,
// positive outside, in metres). Sources, obstacles and regions of every phenomenon are Shapes,
// so they can be rasterised onto any grid (see occupancy.hpp) or queried point by point.
#include "msim/core/grid.hpp"
#include "msim/core/parallel.hpp"
#include "msim/geometry/bounds.hpp"

namespace msim::geometry {

template <int D>
class Shape {
 public:
  virtual ~Shape() = default;

  // Signed distance from x to the surface [m].
  virtual double distance(const Vec<D>& x) const = 0;
  virtual Bounds<D> bounds() const = 0;

  // Signed distance at every cell centre of `spec`. Evaluates distance() per cell; shapes with a
  // cheaper whole-grid method (meshes) override it.
  virtual Grid<float, D> distanceField(const GridSpec<D>& spec) const {
    Grid<float, D> field(spec);
    parallelForCells(field, [&](const IVec<D>& c, std::size_t i) {
      field[i] = static_cast<float>(distance(field.position(c)));
    });
    return field;
  }
};

using Shape2 = Shape<2>;
using Shape3 = Shape<3>;

}  // namespace msim::geometry
