#pragma once
// The scene keys of the "smoke" phenomenon (smoke.*, fire.*, sources[], obstacles[]) and their
// translation into solver parameters. Kept apart from the phenomenon so the schema reads as the
// user's reference (docs/scenes.md is generated from it).
#include <nlohmann/json.hpp>

#include "msim/fluid/smoke/combustion.hpp"
#include "msim/fluid/smoke/smoke_solver.hpp"
#include "msim/fluid/smoke/smoke_turbulence.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

void declareSmokeKeys(Schema& root);

// smoke.* and domain.boundaries as solver parameters; InputError naming the key for combinations
// the schema cannot express (an upwind scheme above CFL 1, a wall velocity on an open side, net
// inflow into a closed box).
template <int D>
fluid::SmokeParams<D> smokeParams(const Scene& scene);

fluid::CombustionParams combustionParams(const nlohmann::json& resolved);

// smoke.turbulence.* (enabled or not).
fluid::SmokeTurbulenceParams smokeTurbulenceParams(const nlohmann::json& resolved);

}  // namespace msim::scene
