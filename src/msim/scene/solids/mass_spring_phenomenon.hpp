#pragma once
// The "cloth" and "solid" phenomena: mass-spring cloth (a triangle mesh with edge and bending
// springs) and solids (BCC tetrahedra with edge and altitude springs) from Selle ch. 5-6
// (solids/), falling onto bodies with friction (ch. 6.5), blown by winds. Keys and outputs:
// docs/cloth.md and docs/solids.md.
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType clothPhenomenonType();
PhenomenonType solidPhenomenonType();

}  // namespace msim::scene
