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

struct SeedOptions {
  double fillFraction = 1.0;  // phi of the seeded material: mass = phi rho_max dx^3 / 8, in (0, 1]
  Vec3 velocity = Vec3::Zero();
  std::uint16_t material = 0;
  std::uint64_t seed = 0;  // jitter stream (core/rng.hpp); the same seed gives the same particles
};

// Seeds 8 particles in every cell of `grid` that overlaps the box [lo, hi], one at a uniformly
// jittered position in each of the cell's 2x2x2 sub-cells, keeping those inside the box for which
// inside(x) holds. Each gets mass fillFraction rho_max dx^3 / 8, the shape A = r^2 I with
// r = dx/4 (the particle radius the seed recommends, seed line 1399) and the given velocity.
// The jitter of a cell depends only on the seed and the cell, so the result does not depend on the
// region's extent or on what was seeded before. Returns the number of particles added.
// std::invalid_argument for an invalid material, a material index outside the table, a fill
// fraction outside (0, 1], or non-finite box or velocity.
std::size_t seedRegion(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                       const std::function<bool(const Vec3&)>& inside, std::span<const GranularMaterial> materials,
                       const SeedOptions& options = {});
std::size_t seedBox(GranularParticles& particles, const GridSpec<3>& grid, const Vec3& lo, const Vec3& hi,
                    std::span<const GranularMaterial> materials, const SeedOptions& options = {});

// The particle radius r of the seed (a quarter of the grid spacing), used by seeding and split/merge.
inline double defaultParticleRadius(double dx) { return 0.25 * dx; }

}  // namespace msim::granular
