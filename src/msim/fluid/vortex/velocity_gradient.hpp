#pragma once
// The velocity gradient G_ij = du_i/dx_j of a MAC velocity at the cell centres, interpolated
// D-linearly to any point (Selle ch. 3.4.1: "computing the derivatives of the velocity field on the
// grid with central differences, trilinearly interpolating them to the particle location"). The
// vortex stretching term is (omega . grad) u = G omega.
//
//   diagonal      du_a/dx_a = (u_a(upper face) - u_a(lower face)) / dx, the staggered difference
//                 (the one the pressure projection's divergence uses);
//   off-diagonal  du_a/dx_b = central difference along b of the face-averaged centre velocity,
//                 one-sided at the border (as computeVorticity in grid_vorticity.hpp does).
// Exact for linear velocity fields, up to float rounding.
//
// Evaluated on demand from the faces around the point (2^D cells, about 30 face reads each in 3D)
// rather than over the whole grid: the particles are few (hundreds to thousands) and the grid
// large, and a full-grid gradient costs 34 ms on a 90x130x90 grid on two cores, the whole of the
// seed's 5% budget.
#include <Eigen/Core>

#include "msim/core/mac_grid.hpp"

namespace msim::fluid {

// G at the centre of cell c.
template <int D>
Eigen::Matrix<double, D, D> cellVelocityGradient(const MacGrid<D>& velocity, const IVec<D>& cell);

// G at a world position, D-linear between the cell centres (clamped to them outside).
template <int D>
Eigen::Matrix<double, D, D> velocityGradientAt(const MacGrid<D>& velocity, const Vec<D>& position);

}  // namespace msim::fluid
