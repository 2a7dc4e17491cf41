#pragma once
// The vorticity omega = curl u (Selle eq. 3.3) of a MAC velocity at the cell centres, shared by
// vorticity confinement, the vortex particles' seeding from the local flow and the enstrophy of
// smoke and liquids: central differences of the face velocities averaged to the centres, one-sided
// at the border. 3 components in 3D; in 2D the scalar omega_z is component 0 of a 1-vector. Exact
// for linear velocity fields away from the border.
#include <Eigen/Core>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/parallel.hpp"

namespace msim::fluid {

template <int D>
using Vorticity = Grid<Eigen::Matrix<float, (D == 3 ? 3 : 1), 1>, D>;

// Central difference of get(g(.)) along `axis` at cell c, one-sided at the border.
template <typename T, int D, typename Get>
auto centralDifference(const Grid<T, D>& g, const IVec<D>& c, int axis, double dx, Get get) {
  IVec<D> lo = c, hi = c;
  if (c[axis] > 0) lo[axis] -= 1;
  if (c[axis] + 1 < g.size()[axis]) hi[axis] += 1;
  const double span = (hi[axis] - lo[axis]) * dx;
  return span > 0.0 ? (get(g(hi)) - get(g(lo))) / span : decltype((get(g(hi)) - get(g(lo))) / span){};
}

// Velocity at cell centres: the mean of the two faces of each axis.
template <int D>
void centreVelocities(const MacGrid<D>& u, Grid<Vecf<D>, D>& centre);

// curl of the centre velocities.
template <int D>
void vorticityFromCentres(const Grid<Vecf<D>, D>& centre, Vorticity<D>& vorticity);

// Both steps with a scratch grid of centre velocities.
template <int D>
void computeVorticity(const MacGrid<D>& velocity, Vorticity<D>& vorticity);

// Enstrophy 1/2 integral |omega|^2 dV [m^3/s^2 in 3D] over the cells i with inside(i) (all of a
// smoke's, a liquid's wet ones).
template <int D, typename Inside>
double enstrophy(const Vorticity<D>& vorticity, Inside&& inside) {
  return 0.5 * vorticity.spec().cellVolume() * parallelSum(vorticity.count(), [&](std::size_t i) {
           return inside(i) ? static_cast<double>(vorticity[i].squaredNorm()) : 0.0;
         });
}

}  // namespace msim::fluid
