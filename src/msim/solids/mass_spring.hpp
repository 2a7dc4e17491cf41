#pragma once
// A mass-spring solid (Selle ch. 5): particles with mass joined by springs. A spring between
// particles 1 and 2 of rest length l0 pulls with the elastic force of eq. 5.1,
//   F = k (|x2 - x1| / l0 - 1) d,  d = (x2 - x1) / |x2 - x1|,
// so k is the force of a spring stretched to twice its length (a strain of 1), and damps only along
// itself (ch. 5.2: isotropic "ether" damping makes objects float),
//   F_d = b ((v2 - v1) . d) d.
// Edge springs of triangles, tetrahedra and segments, and the bending springs that join the
// unshared vertices of two triangles sharing an edge (ch. 5.3.3), are all of this kind. Pinned
// particles do not move (their velocity is kept; scripted ones get it set by the caller).
#include <array>
#include <cstddef>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::solids {

struct Spring {
  int a = 0, b = 0;          // particle indices
  double restLength = 0.0;   // l0 [m]
  double stiffness = 0.0;    // k [N]: the force at a strain of 1 (eq. 5.1)
  double damping = 0.0;      // b [N s/m] along the spring
};

// A tetrahedron's altitude spring (ch. 5.3.4, altitude_spring.hpp): its vertices and the rest
// length of each of its seven altitudes.
struct TetrahedronSpring {
  std::array<int, 4> v{};
  std::array<double, 7> restAltitude{};
  double stiffness = 0.0;  // [N] at an altitude strain of 1
  double damping = 0.0;    // [N s/m] along the altitude
};

// 1 / m per particle, 0 for pinned ones (they take no impulse), into `out`.
void inverseMasses(const std::vector<double>& mass, const std::vector<char>& pinned, std::vector<double>& out);

struct MassSpringSystem {
  std::vector<Vec3> x, v;       // positions [m] and velocities [m/s]
  std::vector<double> mass;     // [kg], > 0
  std::vector<char> pinned;     // 1: the particle does not move under forces
  std::vector<Spring> springs;
  std::vector<TetrahedronSpring> tetrahedra;
  Vec3 gravity = Vec3(0.0, -9.8, 0.0);  // [m/s^2] (the seed's g = 9.8)
  std::vector<Vec3> external;           // per particle [N] (wind drag), held through a step; empty: none

  std::size_t size() const { return x.size(); }
  double inverseMass(std::size_t p) const { return pinned[p] ? 0.0 : 1.0 / mass[p]; }
  // Adds a particle; returns its index.
  int addParticle(const Vec3& position, double particleMass, const Vec3& velocity = Vec3::Zero());
  // Adds a spring between a and b at rest at their current distance. std::invalid_argument for
  // an index out of range, a = b, coincident particles, or stiffness or damping < 0.
  void addSpring(int a, int b, double stiffness, double damping);

  // An altitude spring on the tetrahedron (a, b, c, d) at rest in its current shape.
  // std::invalid_argument for an index out of range, repeated vertices, a rest shape that is
  // inverted (negative volume) or flat, or stiffness or damping < 0.
  void addTetrahedron(const std::array<int, 4>& v, double stiffness, double damping);

  // Elastic (eq. 5.1, and the altitude springs), gravity and external forces at positions `at`
  // [N], into `force`.
  void explicitForces(const std::vector<Vec3>& at, std::vector<Vec3>& force) const;
  // 1/2 m |v|^2 summed [J].
  double kineticEnergy() const;
  // The mass-weighted mean velocity (the centre of mass's) [m/s].
  Vec3 meanVelocity() const;
  // The mass-weighted mean of a velocity per particle (`velocities`, size() of them).
  Vec3 meanVelocity(const std::vector<Vec3>& velocities) const;
  // Elastic energy: for eq. 5.1, k l0 (s^2 / 2) per spring with strain s = |x2 - x1| / l0 - 1, plus
  // the gravitational energy -m g . x [J].
  double potentialEnergy() const;
  // Strain |x2 - x1| / l0 - 1 of spring s.
  double strain(std::size_t s) const;
};

}  // namespace msim::solids
