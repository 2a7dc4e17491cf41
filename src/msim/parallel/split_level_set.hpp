#pragma once
// Redistancing a level set on a split grid (Selle ch. 8.1): each rank fills its ghost layers and
// runs the serial fast marching (numerics::reinitializeFastMarching) on its block with them. A
// cell within k cells of the interface has its nearest interface point within k cells along every
// axis, so its distance equals the serial run's when the ghost layers are at least ceil(k) wide
// (the chapter's rule); beyond, a block does not see interface pieces outside its ghosts.
// Extrapolation along the normals follows the same pattern. Collective.
#include "msim/numerics/level_set/fast_marching.hpp"
#include "msim/parallel/ghost_exchange.hpp"

namespace msim::parallel {

template <int D>
numerics::FastMarchingStats reinitializeSplit(Grid<float, D>& phi, GhostExchange<float, D>& ghosts,
                                              double bandCells) {
  ghosts.exchange(phi);
  return numerics::reinitializeFastMarching<D>(phi, bandCells);
}

}  // namespace msim::parallel
