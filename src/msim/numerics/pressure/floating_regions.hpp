#pragma once
// FloatingRegions<D>: the null space of the pressure matrix. A connected region of fluid cells
// that touches no open (Dirichlet) face - a closed box, or a pocket sealed off by solids - fixes
// its pressure only up to a constant, so the matrix is singular there. Following Selle ch. 4.4.2
// (after the flood fill of the fluid cells), CG still works if the right-hand side is made
// compatible: each floating region's mean is removed from b (zero net divergence), and from every
// preconditioned residual so the iterates never drift along the constant.
#include <cstdint>
#include <vector>

#include "msim/core/mac_grid.hpp"

namespace msim::numerics {

template <int D>
class FloatingRegions {
 public:
  FloatingRegions() = default;
  // faceWeight as for PoissonMatrix: cells connect through faces of positive weight; a region
  // is grounded when one of its domain-boundary faces has positive weight, or one of its cells a
  // positive dirichletDiagonal (PoissonMatrix's: a free surface fixes the pressure as well).
  explicit FloatingRegions(const MacGrid<D>& faceWeight, const std::vector<float>& dirichletDiagonal = {});

  std::size_t count() const { return regions_.size(); }
  const std::vector<std::uint32_t>& cells(std::size_t region) const { return regions_[region]; }
  // Subtract from v its mean over each floating region.
  void removeMeans(std::vector<float>& v) const;

 private:
  std::vector<std::vector<std::uint32_t>> regions_;  // cell indices of each floating region
};

}  // namespace msim::numerics
