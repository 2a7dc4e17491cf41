#pragma once
// Vortex stretching and tilting on the particles (Selle ch. 3.4.1, the (omega . grad) u term of
// eq. 3.4): with G = grad u from the grid (velocityGradientAt: central differences interpolated to x_p),
//   omega_p <- omega_p + dt G(x_p) omega_p,
// then rescaled back to its old magnitude, so the term only turns omega_p. The seed does this in
// all its runs: the ODE grows exponentially where G has a positive eigenvalue, and the particles
// are there to preserve vorticity concentration (clamping or decrease-only are the alternatives it
// names and does not use). If the update gives exactly zero the old vector is kept.
// In 2D the term is identically zero (ch. 3.3) and nothing changes.
#include "msim/fluid/vortex/velocity_gradient.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"

namespace msim::fluid {

// std::invalid_argument if dt is negative or not finite.
template <int D>
void stretchVortexParticles(VortexParticles<D>& particles, const MacGrid<D>& velocity, double dt);

// One particle's update: omega + dt G omega, rescaled to |omega| (exposed for tests and for
// callers with an analytic G).
Eigen::Vector3d stretchAndRescale(const Eigen::Vector3d& omega, const Eigen::Matrix3d& gradient, double dt);

}  // namespace msim::fluid
