#pragma once
// Moving vortex particles with the grid's flow (Selle ch. 3.4.1): "trilinear interpolation is
// used to define a velocity for advecting each particle", the (u . grad) omega term of the
// vorticity equation (3.4). Forward Euler, step 1 of the vortex-particle step of ch. 3.3:
//   x_p^{n+1} = x_p^n + dt u(x_p^n).
#include <cstddef>

#include "msim/core/mac_grid.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"

namespace msim::fluid {

// x_p += dt u(x_p), u sampled D-linearly on the MAC faces. std::invalid_argument if dt is
// negative or not finite.
template <int D>
void advectVortexParticles(VortexParticles<D>& particles, const MacGrid<D>& velocity, double dt);

// Deletes the particles outside the grid's box (they left through an open side); returns how many.
template <int D>
std::size_t removeVortexParticlesOutside(VortexParticles<D>& particles, const GridSpec<D>& domain);

}  // namespace msim::fluid
