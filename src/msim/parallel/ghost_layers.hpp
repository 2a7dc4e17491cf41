#pragma once
// How many ghost layers a scheme reads beyond a block's own samples (Selle ch. 8.1 fills them by
// MPI and leaves their width open). A semi-Lagrangian foot lies at most cfl cells from its sample,
// so its interpolation reads samples at most ceil(cfl) away (an upwind stage: 1); MacCormack runs
// two stages on each other's results and BFECC three, so their reach adds up. The velocity is
// read at the stages' points, on face grids half a cell off the field's lattice: one more layer.
#include <cmath>

#include "msim/numerics/advection/advection_settings.hpp"

namespace msim::parallel {

inline int advectionGhostLayers(const numerics::AdvectionSettings& s, double cfl) {
  const int stages = s.scheme == numerics::AdvectionScheme::FirstOrder ? 1
                     : s.scheme == numerics::AdvectionScheme::MacCormack ? 2
                                                                          : 3;
  const int reach = s.block == numerics::BuildingBlock::Upwind ? 1 : static_cast<int>(std::ceil(cfl));
  return stages * reach + 1;
}

}  // namespace msim::parallel
