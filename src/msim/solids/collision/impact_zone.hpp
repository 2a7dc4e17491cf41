#pragma once
// Rigid impact zones, the fail-safe of cloth collision handling (Provot 1997; Bridson, Fedkiw &
// Anderson 2002 sec. 7.4; Selle ch. 6.3 step C.6): when repulsions and collision impulses leave
// collisions unresolved, the particles of each collision are gathered into a zone, overlapping zones
// are merged, and every zone moves over the step as one rigid body. A rigid body cannot collide with
// itself, so the collisions inside a zone are gone; detection is then repeated, merging zones that
// still collide, until none is left.
//
// The zone's rigid motion keeps its momentum: with v_i = (x1_i - x0_i) / dt the particles' step
// velocities and r_i = x0_i - x_cm their offsets at the start of the step, the zone translates with
// the centre of mass velocity v_cm = sum m_i v_i / M and rotates at the angular velocity
// omega = I^+ L, L = sum m_i r_i x v_i, I = sum m_i (|r_i|^2 Id - r_i r_i^T), so that at the start
// of the step the rigid motion carries the zone's linear momentum M v_cm and angular momentum
// I omega = L. The end positions x_cm + dt v_cm + R(dt omega) r_i use the exact rotation, so the
// distances inside the zone are kept to rounding. (As in the seed, omega is held constant over the
// step, which is the torque-free motion only about a principal axis; the step's average velocities
// then carry the same linear momentum but not exactly the same angular momentum.) I is singular when
// the particles are colinear (no moment about their line) or co-located (no moments at all; coplanar
// particles still have three): the pseudo-inverse drops the missing moments, and those within
// rounding of zero, so such a zone gets no spin about them; L has no component there anyway.
//
// Pinned particles have infinite mass. A zone holding some is dominated by them: the formulas
// above are applied with the pinned particles alone, each weighing the same (the limit of equal
// infinite masses), and the free particles take that rigid motion while the pinned ones keep their
// prescribed end positions. So a zone touching still pins stays still and one touching a single
// moving pin translates with it; several moving pins give it the rigid motion of their own
// momentum, which follows pins that turn rigidly with an error of second order in their angle.
#include <span>
#include <vector>

#include "msim/core/disjoint_sets.hpp"
#include "msim/core/vec.hpp"

namespace msim::solids {

struct RigidZoneMotion {
  Vec3 centreOfMass = Vec3::Zero();     // at the start of the step
  Vec3 velocity = Vec3::Zero();         // of the centre of mass
  Vec3 angularVelocity = Vec3::Zero();  // omega, about the centre of mass
};

// The rigid motion of `zone` (particle indices; x0 and x1 the start and candidate end positions, dt
// the step) that keeps its momentum; pinned[i] != 0 marks particle i as pinned (see above).
RigidZoneMotion rigidZoneMotion(std::span<const int> zone, const std::vector<double>& mass,
                                const std::vector<char>& pinned, const std::vector<Vec3>& x0,
                                const std::vector<Vec3>& x1, double dt);

// Replaces the end positions x1 of the zone's free particles by the zone's rigid motion.
void applyRigidImpactZone(std::span<const int> zone, const std::vector<double>& mass, const std::vector<char>& pinned,
                          const std::vector<Vec3>& x0, std::vector<Vec3>& x1, double dt);

// The zones as collisions accumulate (union-find): a collision joins its particles' zones into one.
class ImpactZones {
 public:
  explicit ImpactZones(int particleCount);

  // The particles of one collision: a point and a triangle's vertices, or two edges' vertices.
  void addCollision(std::span<const int> particles);

  // The zones, each sorted, ordered by their smallest particle; a particle in no collision is in none.
  std::vector<std::vector<int>> zones() const;

 private:
  DisjointSets sets_;
  std::vector<char> collided_;
};

}  // namespace msim::solids
