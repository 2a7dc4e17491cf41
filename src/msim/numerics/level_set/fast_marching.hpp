#pragma once
// Reinitialisation of a level set to signed distance by fast marching (Sethian 1996), in a narrow
// band around its zero crossing, as Selle ch. 4.4.3 reinitialises the water's phi after every
// advection (the velocity extrapolation ordered by phi relies on it):
//
//  1. Interface cells - those with a neighbour of the other sign - keep their zero crossing: along
//     each axis the crossing towards the nearer opposite-signed neighbour lies at
//     d_a = dx * phi_i / (phi_i - phi_nb) (linear interpolation), and the cell's distance is that
//     to the plane through the crossings, d = (sum_a d_a^-2)^-1/2 (exact for a planar interface).
//  2. The rest of the band is accepted in order of increasing distance from a binary heap, each
//     cell updated from its accepted neighbours by the first-order upwind discretisation of
//     |grad d| = 1 (the quadratic in the smallest neighbour per axis, solved with one, two, then
//     three of them while the root stays above the next one).
//  3. Cells farther than the band keep their sign at +-band.
//
// The sign of every cell is kept, so the interface moves only by the change of the crossings'
// positions: not at all for the interface cells' own crossings (their values are recomputed from
// them). Works for any sample layout of the grid (cell centres, faces, nodes): spacing spec.dx.
#include <cstddef>

#include "msim/core/grid.hpp"

namespace msim::numerics {

struct FastMarchingStats {
  std::size_t interfaceCells = 0;  // cells next to a sign change (step 1)
  std::size_t marchedCells = 0;    // cells accepted by the march within the band (step 2)
};

// phi: any function with the interface at its zero crossing (phi < 0 inside); replaced by the
// signed distance within bandCells * dx of the interface and by +-bandCells * dx beyond.
// std::invalid_argument for bandCells <= 0 or a non-finite phi.
template <int D>
FastMarchingStats reinitializeFastMarching(Grid<float, D>& phi, double bandCells);

}  // namespace msim::numerics
