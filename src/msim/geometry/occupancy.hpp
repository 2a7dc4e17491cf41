#pragma once
// Solid fraction of each grid cell from a shape's signed distance: 1 deep inside, 0 outside, and
// a linear ramp 0.5 - d/dx across the one cell the surface passes through. The ramp is the exact
// covered fraction for a surface parallel to the cell faces and close for smooth surfaces, so the
// rasterised volume does not jump cell by cell as a shape moves or the resolution changes.
#include <algorithm>

#include "msim/geometry/shape.hpp"

namespace msim::geometry {

template <int D>
Grid<float, D> occupancy(const Shape<D>& shape, const GridSpec<D>& spec) {
  Grid<float, D> fraction = shape.distanceField(spec);
  const float invDx = static_cast<float>(1.0 / spec.dx);
  parallelFor(0, fraction.count(), [&](std::size_t i) { fraction[i] = std::clamp(0.5f - fraction[i] * invDx, 0.0f, 1.0f); });
  return fraction;
}

}  // namespace msim::geometry
