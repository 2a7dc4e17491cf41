#pragma once
// The keys smoke.turbulence and liquid.turbulence share (Narain ch. 3: the energy model and the
// noise particles) and their translation into the turbulence module's parameters.
#include <nlohmann/json.hpp>

#include "msim/scene/schema/schema.hpp"
#include "msim/turbulence/subgrid_turbulence.hpp"

namespace msim::scene {

// enabled, refinement, largest_eddy, viscosity (defaultViscosity: the medium's), the eddy
// viscosity constant, initial_energy, intensity, octaves, seed. `enabledNote` says what turning it
// on changes for the phenomenon.
void declareSubgridTurbulenceKeys(Schema& turbulence, const char* enabledNote, double defaultViscosity);

// The keys of declareSubgridTurbulenceKeys read from a resolved turbulence object.
turbulence::SubgridTurbulenceParams subgridTurbulenceParams(const nlohmann::json& turbulence);

}  // namespace msim::scene
