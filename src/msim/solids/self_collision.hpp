#pragma once
// Step C of the cloth's collision loop (Selle ch. 6.3, after Bridson, Fedkiw & Anderson 2002
// secs. 6-7.4): the cloth moved from a collision-free state x0 to x1 over the outer step; each
// particle is taken to move on a straight line between them, with the effective velocity
// (x1 - x0) / T. Passes of continuous collision detection (swept boxes, the coplanarity cubic)
// then find every point-triangle and edge-edge crossing; each is resolved Gauss-Seidel, in order,
// by an inelastic impulse that sets the pair's relative normal velocity to zero, followed, when the
// pair would end closer than the thickness, by the repulsion of eq. 6.1 computed with the average
// inner step (not the whole elapsed time, ch. 6.3 C.4). Later passes look only at pairs with a
// particle that moved. When crossings remain after the Gauss-Seidel passes, the particles of the
// colliding pairs are merged into rigid impact zones (Provot 1997) that move with their
// momentum's rigid motion (inertia inverted by SVD pseudo-inverse, collision/impact_zone.hpp);
// zones grow and merge until no crossing is left. Particles that the pairwise impulses push into
// a body are put back on its surface before the next pass looks again (zones move rigidly and are
// left alone). Unlike Bridson et al. there is no rewind or
// step halving: the inner step count stays fixed (ch. 6.3).
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/solids/body_contact.hpp"
#include "msim/solids/collision_pairs.hpp"
#include "msim/solids/particle_split.hpp"
#include "msim/solids/self_repulsion.hpp"

namespace msim::solids {

struct SelfCollisionSettings {
  int gaussSeidelPasses = 8;   // passes of pairwise impulses before impact zones take over
  int impactZonePasses = 64;   // passes of growing zones before giving up
  double tolerance = 1e-6;     // [m]: coplanar primitives this close count as touching
};

struct SelfCollisionStats {
  int collisions = 0;    // crossings found, summed over the passes
  int passes = 0;        // detection passes run
  int impactZones = 0;   // zones in the last pass that used them
  int zoneParticles = 0; // particles in those zones
  int unresolved = 0;    // crossings left after the last pass (0 unless the loop gave up)
};

class SelfCollisionResolver {
 public:
  explicit SelfCollisionResolver(const SelfCollisionSettings& settings = {}) : settings_(settings) {}
  // Splits the detection among processes (particle_split.hpp; null: this process alone): each
  // finds the candidates and tests the crossings of its own points and of the edges whose first
  // vertex it owns, and all join them; the impulses and impact zones run alike on every process.
  void setSplit(const ParticleSplit* split) { split_ = split; }

  // Makes x1 collision-free relative to x0 (itself collision-free). T: the outer step [s];
  // innerDt: the average inner step; repulsion: the thickness and stiffness of eq. 6.1; pinned
  // particles (inverseMass 0) keep their x1.
  SelfCollisionStats resolve(CollisionPairs& pairs, const std::vector<Vec3>& x0, std::vector<Vec3>& x1,
                             const std::vector<double>& mass, const std::vector<char>& pinned, double T, double innerDt,
                             const RepulsionSettings& repulsion, const BodyContact* bodies = nullptr);

 private:
  struct Crossing {
    bool pointTriangle = true;
    int first = 0, second = 0;  // point and triangle, or the two edges
  };
  // The crossings among the candidate pairs, in the pairs' order.
  void detect(const CollisionPairs& pairs, const std::vector<Vec3>& x0, const std::vector<Vec3>& x1);
  // Resolves one crossing if it is still there; returns whether it was.
  bool respond(const CollisionPairs& pairs, const Crossing& c, const std::vector<Vec3>& x0, std::vector<Vec3>& x1,
               double T, double innerDt, const RepulsionSettings& repulsion);
  std::array<int, 4> particles(const CollisionPairs& pairs, const Crossing& c) const;

  SelfCollisionSettings settings_;
  std::vector<PointTrianglePair> candidatesPointTriangle_;
  std::vector<EdgeEdgePair> candidatesEdgeEdge_;
  std::vector<Crossing> crossings_;
  std::vector<char> hit_, moved_, movedThisPass_;
  std::vector<double> inverseMass_;
  std::vector<Vec3> velocity_;
  const ParticleSplit* split_ = nullptr;
};

}  // namespace msim::solids
