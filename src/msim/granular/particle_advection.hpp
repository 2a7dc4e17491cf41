#pragma once
// Particle advection of the granular scheme (Narain 2011 ch. 5.4, seed lines 1382-1384, and the
// shape evolution of eq. 5.42): first the density-correction displacement dx_corr of eq. 5.14 is
// applied, then the particle moves with the grid velocity (forward Euler), and its shape follows
// the local velocity gradient.
#include <span>

#include <Eigen/Core>

#include "msim/core/mac_grid.hpp"
#include "msim/granular/granular_particles.hpp"

namespace msim::granular {

// The trilinear interpolant of a MAC velocity (core/interpolation.hpp sampleLinear: each component
// on its own face grid, positions clamped onto the sample range) and its exact derivative,
// J(a, b) = d v_a / d x_b. Along an axis where x lies outside a face grid's sample range the
// interpolant is constant, so that column of the derivative is 0 for that component.
struct VelocitySample {
  Vec3 value;
  Eigen::Matrix3d jacobian;
};
VelocitySample sampleVelocityAndJacobian(const MacGrid<3>& velocity, const Vec3& x);

// One forward-Euler step of eq. 5.42, dA/dt = A J^T + J A, written as A <- F A F^T with
// F = I + dt J. The two agree to first order in dt (F A F^T = A + dt (J A + A J^T) + dt^2 J A J^T),
// but the product form keeps A exactly symmetric and, since F is invertible for dt |J| < 1,
// positive definite, which the additive update does not guarantee under strong compression.
Eigen::Matrix3d deformShape(const Eigen::Matrix3d& a, const Eigen::Matrix3d& jacobian, double dt);

// Particles and points are kept inside the velocity grid's domain box, this many cells inside its
// faces, so that every later transfer sees them within the grid.
inline constexpr double kBoundaryEpsilonCells = 1e-3;
Vec3 clampIntoDomain(const GridSpec<3>& domain, const Vec3& x);

// x <- clamp(x + dx_corr(x)); then A <- F A F^T with F = I + dt J_v(x) and x <- clamp(x + dt v(x)),
// v and J_v interpolated trilinearly at the corrected position. `displacement` (optional) is the
// density-correction displacement on a MAC grid of the same domain [m]. Parallel.
void advectParticles(GranularParticles& particles, const MacGrid<3>& velocity, double dt,
                     const MacGrid<3>* displacement = nullptr);

// The same motion for passive points (render points): positions only.
void advectPoints(std::span<Vecf<3>> points, const MacGrid<3>& velocity, double dt,
                  const MacGrid<3>* displacement = nullptr);

}  // namespace msim::granular
