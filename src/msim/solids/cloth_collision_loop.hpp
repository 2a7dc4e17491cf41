#pragma once
// The outer collision loop of high-resolution cloth (Selle ch. 6.2-6.3): one outer step of
// duration T is
//   A. find the point-triangle and edge-edge pairs that may come within the thickness during the
//      step (bounding-volume trees, pruned loosely) and remember their sides (self_repulsion.hpp);
//   B. k_i inner Newmark steps of T / k_i with body contact and friction, and the pairs'
//      repulsions on the position and end velocities (newmark.hpp), strain limiting after each;
//   C. continuous collision detection from the collision-free start to the end, with impulses
//      and rigid impact zones (self_collision.hpp); the particles it moved take the change of
//      position over T as a change of velocity.
// The cloth is collision-free at the start and the end of every outer step; k_i stays fixed (the
// seed's 4-16, normally 16) instead of rewinding steps that collide. The pairs of step A are
// those within the thickness of each other somewhere along the particles' predicted paths over
// the step relative to the cloth's mean motion (a cloth falling as a whole brings no pair
// closer); CCD catches the rest. Each stage's wall time is
// kept, for the seed's Table 6.3 split.
#include <array>
#include <functional>
#include <vector>

#include "msim/solids/body_contact.hpp"
#include "msim/solids/collision_pairs.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/newmark.hpp"
#include "msim/solids/self_collision.hpp"
#include "msim/solids/self_repulsion.hpp"

namespace msim::solids {

struct ClothCollisionSettings {
  int innerSteps = 16;       // k_i (see step())
  RepulsionSettings repulsion;
  SelfCollisionSettings collision;
  double strainLimit = 0.0;  // 0: off (strain_limit.hpp)
  int strainLimitSweeps = 50;
};

struct ClothCollisionStats {
  NewmarkStats newmark;               // summed over the inner steps (contacts: the last one's)
  int pointTrianglePairs = 0, edgeEdgePairs = 0;  // step A
  int innerSteps = 0;                 // taken
  int repulsions = 0;                 // pairs closer than the thickness, summed over the inner steps
  SelfCollisionStats collisions;      // step C
  double secondsPairs = 0.0, secondsInner = 0.0, secondsCollisions = 0.0;  // Table 6.3's A, B, C
};

class ClothCollisionLoop {
 public:
  // The cloth's triangles over the system's particles.
  ClothCollisionLoop(std::vector<std::array<int, 3>> triangles, std::size_t particleCount, const NewmarkSettings& newmark,
                     const ClothCollisionSettings& settings);

  // One outer step of T (> 0) against `bodies` (may be null), in inner steps that split what is
  // left of T equally within the stable step innerLimit(), asked before each (the cloth's tension
  // changes it). The caller makes T about k_i stable steps; a step cut short by a frame's end
  // takes fewer.
  // placeBodies(t), when given, is called before each inner step with the time t (from the outer
  // step's start) at which it ends, so that moving bodies stand where the step ends (ch. 6.5).
  ClothCollisionStats step(MassSpringSystem& system, double T, const std::function<double()>& innerLimit,
                           const BodyContact* bodies, const std::function<void(double)>& placeBodies = {});

  const ClothCollisionSettings& settings() const { return settings_; }
  // Splits the search for pairs and crossings (steps A and C), the inner steps' solves and the
  // repulsions among processes (particle_split.hpp; null: this process alone).
  void setSplit(const ParticleSplit* split) {
    stepper_.setSplit(split);
    repulsion_.setSplit(split);
    resolver_.setSplit(split);
  }

 private:
  ClothCollisionSettings settings_;
  CollisionPairs pairs_;
  SelfRepulsion repulsion_;
  SelfCollisionResolver resolver_;
  NewmarkStepper stepper_;
  std::vector<Vec3> start_, before_, predicted_;
};

}  // namespace msim::solids
