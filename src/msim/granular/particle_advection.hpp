#pragma once
// Particle advection of the granular scheme (Narain 2011 ch. 5.4, seed lines 1382-1384, and the
// shape evolution of eq. 5.42): first the density-correction displacement dx_corr of eq. 5.14 is
// applied, then the particle moves with the grid velocity (forward Euler), and its shape follows
// the local velocity gradient.
#include <span>
#include <vector>

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
// Inline: it runs for every particle and render point of every step.
inline Vec3 clampIntoDomain(const GridSpec<3>& domain, const Vec3& x) {
  const double eps = kBoundaryEpsilonCells * domain.dx;
  const Vec3 lo = domain.origin.array() + eps, hi = domain.upper().array() - eps;
  return x.cwiseMax(lo).cwiseMin(hi);
}

// What one particle's step did, for the points it carries (render points): its position before
// the step, its correction displacement, and the velocity and velocity gradient it moved with.
struct ParticleMotion {
  Vec3 start, displacement, velocity;
  Eigen::Matrix3d jacobian;
};

// x <- clamp(x + dx_corr); then A <- F A F^T with F = I + dt J_v(x) and x <- clamp(x + dt v(x)),
// v and J_v interpolated trilinearly at the corrected position. `displacement` (empty: none) is
// each particle's density-correction displacement dx_corr [m], as sampleCorrection gives it.
// `motion` (optional) receives each particle's ParticleMotion. Parallel.
void advectParticles(GranularParticles& particles, const MacGrid<3>& velocity, double dt,
                     std::span<const Vec3> displacement = {}, std::vector<ParticleMotion>* motion = nullptr);

// The density-correction displacement (a MAC grid of the particles' domain) interpolated
// trilinearly at each particle (sampleLinear), into `out`. Parallel.
void sampleCorrection(const GranularParticles& particles, const MacGrid<3>& displacement, std::vector<Vec3>& out);

// A point carried by a particle (render points, ch. 5.6) after the particle's step `m`:
// clamp(x + dx_p + dt (v_p + J_p (x - x_p))), the first-order expansion of the grid motion about
// the particle. It is the map that deforms the particle's ellipsoid (x_p + r -> x_p' + F r,
// F = I + dt J_p), so a point inside its particle stays inside (up to the clamp into the domain
// and the particle's push out of solids), and it costs a 3x3 product where sampling the grid
// twice (velocity and correction) cost about ten times more.
inline Vec3 carriedPosition(const ParticleMotion& m, const Vec3& x, double dt, const GridSpec<3>& domain) {
  const Vec3 r = x - m.start;
  return clampIntoDomain(domain, m.start + m.displacement + r + dt * (m.velocity + m.jacobian * r));
}

}  // namespace msim::granular
