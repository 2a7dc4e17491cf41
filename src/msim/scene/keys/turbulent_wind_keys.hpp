#pragma once
// The scene keys of turbulent winds (winds[], Stam ch. 3.4 and 6.3.2), shared by every phenomenon
// that can be blown by one (gas: added to the motion field; smoke: a drag force), and their
// translation into placed spectral winds.
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/scene/schema/schema.hpp"
#include "msim/turbulence/turbulent_wind.hpp"

namespace msim::scene {

struct Scene;

void declareTurbulentWinds(Schema& root);

// Synthesises every wind of the resolved scene's winds[]; InputError naming the file and
// winds[i] for a spectrum the lattice cannot hold or inconsistent parameters.
template <int D>
std::vector<turbulence::TurbulentWind<D>> turbulentWinds(const Scene& scene);

}  // namespace msim::scene
