#pragma once
// Scene keys of the "granular" phenomenon (gravity, granular.*, materials[], regions[],
// explosions[], solids[], bodies[]) and their translation into a seeded, ready-to-step
// granular::GranularSimulation, with errors that name the key (the library's
// std::invalid_argument becomes an InputError naming the scene key that caused it).
#include <memory>
#include <string>
#include <vector>

#include "msim/geometry/shape.hpp"
#include "msim/granular/granular_simulation.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

// explosions[]: at `time` the particles (and body centres) within `radius` of `centre` gain an
// outward radial velocity `speed` (Narain 2011 Fig. 5.1 as an instantaneous impulse).
struct GranularExplosion {
  Vec3 centre = Vec3::Zero();
  double radius = 0.0, speed = 0.0, time = 0.0;
};

struct GranularSceneSetup {
  std::unique_ptr<granular::GranularSimulation> sim;  // solids, bodies and particles in place
  std::vector<std::string> materialNames;
  std::vector<Vec3> colours;  // linear RGB per material, for the preview
  std::vector<GranularExplosion> explosions;
  std::vector<int> bodies;    // world indices of bodies[], in scene order
  std::vector<std::shared_ptr<const geometry::Shape<3>>> solids;  // solids[] as the material sees them
  double maxStep = 0.01;      // [s]
};

void declareGranularKeys(Schema& root);
// Throws InputError naming the scene file and key for any inconsistency.
GranularSceneSetup buildGranularScene(const Scene& scene);

}  // namespace msim::scene
