#pragma once
// How many ghost layers a scheme reads beyond a block's own samples (Selle ch. 8.1 fills them by
// MPI and leaves their width open). A semi-Lagrangian foot lies at most cfl cells from its sample,
// so its interpolation reads samples at most ceil(cfl) away (an upwind stage: 1); MacCormack runs
// two stages on each other's results and BFECC three, so their reach adds up. The velocity is
// read at the stages' points, on face grids half a cell off the field's lattice: one more layer.
#include <algorithm>
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

// Vorticity confinement (Selle eq. 3.3) differences the velocity three times on its way to a
// face: cell-centred velocity, its curl, the gradient of |curl|; the force is then averaged
// onto faces. An owned face reads samples up to three cells away.
constexpr int kConfinementGhostLayers = 3;

// The conservative scalar transport (numerics/flux_transport.hpp): a face's MUSCL value reads the
// two cells on either side of it, so each SSP-RK2 stage moves a cell by what lies up to two cells
// away, and the two stages of a substep four; the fields' ghosts are refreshed before every substep.
constexpr int kFluxTransportGhostLayers = 4;

// The ghost layers a smoke step reads: its advection scheme's, confinement's or (with the
// conservative scalar transport) the flux transport's, whichever is widest.
inline int smokeGhostLayers(const numerics::AdvectionSettings& s, double cfl, bool conservativeScalars = false) {
  return std::max({advectionGhostLayers(s, cfl), kConfinementGhostLayers, conservativeScalars ? kFluxTransportGhostLayers : 0});
}

// The ghost layers a liquid step (particle level set) reads: its advection's, and ceil(band) for
// the fast marching's band of distances (Selle ch. 8.1: a band of k valid cells needs ceil(k)
// layers), within which the velocity extension (narrower than the band) also stays.
inline int liquidGhostLayers(const numerics::AdvectionSettings& s, double cfl, double bandCells) {
  return std::max(advectionGhostLayers(s, cfl), static_cast<int>(std::ceil(bandCells)));
}

}  // namespace msim::parallel
