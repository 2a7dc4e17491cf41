#pragma once
// Open face fractions of a MAC grid cut by solids (Batty, Bertails & Bridson 2007; Bridson's
// fluid notes, "variational pressure"). The pressure solve weights each face by the fraction of
// its area that lies in fluid, so a curved obstacle enters the Poisson matrix smoothly instead of
// as a staircase of whole solid cells, and a face that is entirely inside the solid carries no
// fluid flux at all (no leaks).
//
// The solid is given by a signed distance phi sampled at the grid nodes (cell corners), negative
// inside the solid. Along a face edge phi is taken linear, so the fraction is exact for planar
// solid boundaries.
#include <utility>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/parallel.hpp"

namespace msim::numerics {

// Fraction of the segment [0,1] where the linear interpolant of (phiA, phiB) is negative.
float fractionInside(float phiA, float phiB);
// Fraction of the unit square where the bilinear data (corner values in the order lower-left,
// lower-right, upper-left, upper-right) is negative; exact for planar phi.
float fractionInside(float phiLL, float phiLR, float phiUL, float phiUR);

// Nodal samples (res+1 per axis, offset 0) of a solid signed distance: sdf(x) < 0 inside.
template <int D, typename F>
Grid<float, D> sampleNodes(const GridSpec<D>& spec, F&& sdf) {
  Grid<float, D> phi(spec, (spec.res.array() + 1).matrix(), Vec<D>::Zero());
  parallelForCells(phi, [&](const IVec<D>& n, std::size_t lin) { phi[lin] = static_cast<float>(sdf(phi.position(n))); });
  return phi;
}

// Per-face open (fluid) fraction in [0,1] from nodal solid phi (see sampleNodes).
template <int D>
MacGrid<D> openFaceFractions(const GridSpec<D>& spec, const Grid<float, D>& nodalSolidPhi);

// Solid cell mask (1 solid, 0 fluid) from nodal solid phi: a cell is solid when the D-linear
// interpolant of phi is negative at its centre, i.e. the mean of its 2^D corners is.
template <int D>
void solidCellsFromNodes(const Grid<float, D>& nodalSolidPhi, Grid<float, D>& solid) {
  parallelForCells(solid, [&](const IVec<D>& c, std::size_t lin) {
    double mean = 0.0;
    for (int k = 0; k < (1 << D); ++k) {
      IVec<D> n = c;
      for (int a = 0; a < D; ++a) n[a] += (k >> a) & 1;
      mean += nodalSolidPhi(n);
    }
    solid[lin] = mean < 0.0 ? 1.0f : 0.0f;
  });
}

// Open fractions for a solid given as a signed distance function of world position.
template <int D, typename F>
MacGrid<D> openFaceFractionsFromSdf(const GridSpec<D>& spec, F&& sdf) {
  return openFaceFractions<D>(spec, sampleNodes<D>(spec, std::forward<F>(sdf)));
}

}  // namespace msim::numerics
