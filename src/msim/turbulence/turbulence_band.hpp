#pragma once
// Where procedural turbulence is synthesised (Narain 2011, ch. 3.5): u' matters only where it
// moves something the user sees (smoke, a liquid's surface), so the noise potential is evaluated
// on the fine nodes near those coarse cells and nowhere else. The caller marks the coarse cells
// that carry what is seen; the band grows them by one cell and by the distance the fastest face
// covers in a step (the "core", full u'), and tapers the potential linearly to zero over two more
// cells, so the band's edge makes no sheet of velocity (cutting psi off from one fine node to the
// next would put about twice the eddies' speed on it). Used by the smoke's and the liquid's
// sub-grid turbulence.
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim::turbulence {

template <int D>
class TurbulenceBand {
 public:
  // refinement: fine cells per coarse cell and axis (>= 1).
  TurbulenceBand(const GridSpec<D>& coarse, int refinement);

  // seeds: one flag per coarse cell (x fastest), non-zero where u' is wanted. velocity: the
  // coarse face velocities of the step, dt its length (the core's reach).
  void mark(const std::vector<std::uint8_t>& seeds, const MacGrid<D>& velocity, double dt);

  // The potential's weight at the fine nodes (fine res + 1 per axis, x fastest): 1 in the core,
  // 0 beyond the taper; NoiseParticles::synthesize's nodeWeight.
  const std::vector<float>& nodeWeight() const { return nodeWeight_; }
  // The core's bounding box in coarse cells [lo, hi), rounded out to blocks of four cells so that a
  // window over it changes only every few steps; lo == hi when nothing is marked.
  const IVec<D>& lo() const { return lo_; }
  const IVec<D>& hi() const { return hi_; }
  bool empty() const { return lo_ == hi_; }
  // Fraction of the fine nodes with a non-zero weight.
  double fraction() const { return fraction_; }

 private:
  GridSpec<D> coarse_;
  int refinement_;
  std::vector<std::uint8_t> level_, scratch_;  // each coarse cell's distance to the seeds (cells)
  std::vector<float> coarseNodeWeight_, nodeWeight_;
  IVec<D> lo_ = IVec<D>::Zero(), hi_ = IVec<D>::Zero();
  double fraction_ = 0.0;
};

extern template class TurbulenceBand<2>;
extern template class TurbulenceBand<3>;

}  // namespace msim::turbulence
