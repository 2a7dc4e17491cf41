#pragma once
// Simulation particles of a granular material (Narain 2011 ch. 5.4, seed lines 1376-1407): each
// particle is a macroscopic clump of grains with mass m_i, centre x_i, average velocity v_i and an
// ellipsoidal shape (x - x_i)^T A_i^{-1} (x - x_i) <= 1 that the flow stretches (eq. 5.42) and
// split/merge keeps near a sphere of radius r.
//
// Structure of arrays in float (like core/particles.hpp; positions and velocities at simulation
// scales need no more), with the material as an index into a table of GranularMaterial so that
// rho_max and the friction coefficient are not stored per particle.
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>
#include <functional>
#include <span>
#include <vector>

#include <Eigen/Core>

#include "msim/core/grid_spec.hpp"
#include "msim/core/vec.hpp"

namespace msim::granular {

struct GranularMaterial {
  double density = 1600.0;  // rho_max [kg/m^3], the density of the fully packed material, > 0
  double friction = 0.6;    // alpha: friction coefficient of the yield condition (eq. 5.15), in [0, 2]
};

// std::invalid_argument naming the material and the offending field (density <= 0, friction
// outside [0, 2], NaN).
void validate(const GranularMaterial& material, std::size_t index = 0);
void validate(std::span<const GranularMaterial> materials);

// Symmetric 3x3 shape matrix stored as (xx, yy, zz, xy, xz, yz).
using ParticleShape = std::array<float, 6>;
Eigen::Matrix3d shapeMatrix(const ParticleShape& s);
ParticleShape toShape(const Eigen::Matrix3d& a);  // reads the upper triangle

struct GranularParticles {
  std::vector<Vecf<3>> position;  // [m]
  std::vector<Vecf<3>> velocity;  // [m/s]
  std::vector<float> mass;        // [kg]
  std::vector<ParticleShape> shape;       // A_i [m^2]
  std::vector<std::uint16_t> material;

  std::size_t size() const { return position.size(); }
  bool empty() const { return position.empty(); }
  void resize(std::size_t n);
  void reserve(std::size_t n);
  void clear() { resize(0); }
  std::size_t append(const Vecf<3>& x, const Vecf<3>& v, float m, const ParticleShape& a, std::uint16_t materialIndex);
  // Copies particle `from` of `source` into slot `to` of this set (which must be large enough).
  void copyFrom(const GranularParticles& source, std::size_t from, std::size_t to);
};

// Seeding density: the seed's particle radius r = dx/4 (seed line 1399) is 8 particles per cell.
inline constexpr double kDefaultParticlesPerCell = 8.0;
inline constexpr double kMaxParticlesPerCell = 125.0;  // r >= dx/10

struct SeedOptions {
  double fillFraction = 1.0;  // phi of the seeded material: mass = phi rho_max h^3, in (0, 1]
  // k, in [1, kMaxParticlesPerCell]: the particle spacing h = dx / cbrt(k). GranularSimulation::seed
  // uses its settings' value instead.
  double particlesPerCell = kDefaultParticlesPerCell;
  Vec3 velocity = Vec3::Zero();
  std::uint16_t material = 0;
  std::uint64_t seed = 0;  // jitter stream (core/rng.hpp); the same seed gives the same particles
};

// Seeds particlesPerCell particles per cell on average over the part of the box [lo, hi] inside
// `grid`: one at a uniformly jittered position in each cube of a lattice of spacing
// h = dx / cbrt(particlesPerCell) anchored at the grid origin (at 8 per cell, the cells' 2x2x2
// sub-cells), keeping those inside the box for which inside(x) holds. Each gets mass
// fillFraction rho_max h^3, the spherical shape A = r^2 I with r = h/2 (particleRadius) and the
// given velocity. The jitter of a lattice cube depends only on the seed and the cube, so the result
// does not depend on the region's extent or on what was seeded before. Returns the number of
// particles added. std::invalid_argument for an invalid material, a material index outside the
// table, a fill fraction outside (0, 1], a density outside [1, kMaxParticlesPerCell], or non-finite
// box or velocity.
std::size_t seedRegion(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                       const std::function<bool(const Vec3&)>& inside, std::span<const GranularMaterial> materials,
                       const SeedOptions& options = {});
std::size_t seedBox(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                    std::span<const GranularMaterial> materials, const SeedOptions& options = {});

// The particle spacing h = dx / cbrt(k) of k particles per cell, and the particle radius r = h/2 that
// seeding and split/merge use: the seed's user parameter r (ch. 5.4.1), a quarter of the grid
// spacing at the default 8 per cell.
inline double particleSpacing(double dx, double particlesPerCell = kDefaultParticlesPerCell) {
  return dx / std::cbrt(particlesPerCell);
}
inline double particleRadius(double dx, double particlesPerCell = kDefaultParticlesPerCell) {
  return 0.5 * particleSpacing(dx, particlesPerCell);
}
// std::invalid_argument unless k lies in [1, kMaxParticlesPerCell].
void validateParticlesPerCell(double particlesPerCell);

}  // namespace msim::granular
