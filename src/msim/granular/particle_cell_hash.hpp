#pragma once
// Uniform cell list over 3D particle positions for nearest-neighbour queries (merge partners):
// built by the stable counting sort of core/bucket_sort.hpp, O(n), deterministic, and without
// allocation once its buffers are warm.
#include <algorithm>
#include <cstdint>
#include <span>

#include "msim/core/bucket_sort.hpp"
#include "msim/core/vec.hpp"

namespace msim::granular {

class ParticleCellHash {
 public:
  // Buckets the (finite) positions into cubic cells of side at least `cellSize` (> 0) over their
  // bounding box. The side grows when the box would need more than one cell per two points, which
  // bounds the memory for sparse clouds; queries stay exact for radii <= cellSize either way.
  void build(std::span<const Vecf<3>> positions, double cellSize);

  // f(j) for the built points j in the 3x3x3 cells around x (a superset of the points within
  // cellSize of x), for nearest-point searches: x's own cell first, then the others in cell
  // order, input order within a cell (deterministic), skipping a cell all of whose box lies
  // farther from x than sqrt(bound2()) (read before each cell, so f may lower it as it finds
  // closer points). Every point at squared distance <= bound2() is still visited, so the nearest
  // one, ties included, is found as by visiting all 27 cells.
  template <typename Bound, typename F>
  void forEachNearWithin(const Vec3& x, const Bound& bound2, F&& f) const;

 private:
  IVec3 cellOf(const Vec3& x) const {
    IVec3 c;
    for (int a = 0; a < 3; ++a) c[a] = std::clamp(static_cast<int>((x[a] - origin_[a]) / side_), 0, cells_[a] - 1);
    return c;
  }
  std::size_t linear(const IVec3& c) const {
    return static_cast<std::size_t>(c[0]) +
           static_cast<std::size_t>(cells_[0]) * (static_cast<std::size_t>(c[1]) + static_cast<std::size_t>(cells_[1]) * c[2]);
  }

  Vec3 origin_ = Vec3::Zero();
  double side_ = 1.0;
  IVec3 cells_ = IVec3::Ones();
  BucketSort sort_;
};

template <typename Bound, typename F>
void ParticleCellHash::forEachNearWithin(const Vec3& x, const Bound& bound2, F&& f) const {
  const IVec3 c = cellOf(x);
  const std::span<const std::uint32_t> order = sort_.order();
  auto visit = [&](const IVec3& q) {
    const std::size_t cell = linear(q);
    for (std::size_t k = sort_.begin(cell); k < sort_.begin(cell + 1); ++k) f(order[k]);
  };
  visit(c);
  IVec3 q;
  for (q[2] = std::max(c[2] - 1, 0); q[2] <= std::min(c[2] + 1, cells_[2] - 1); ++q[2])
    for (q[1] = std::max(c[1] - 1, 0); q[1] <= std::min(c[1] + 1, cells_[1] - 1); ++q[1])
      for (q[0] = std::max(c[0] - 1, 0); q[0] <= std::min(c[0] + 1, cells_[0] - 1); ++q[0]) {
        if (q == c) continue;
        double gap2 = 0.0;  // squared distance from x to the cell's box
        for (int a = 0; a < 3; ++a) {
          const double lo = origin_[a] + q[a] * side_, hi = lo + side_;
          const double gap = std::max({0.0, lo - x[a], x[a] - hi});
          gap2 += gap * gap;
        }
        if (gap2 > bound2()) continue;
        visit(q);
      }
}

}  // namespace msim::granular
