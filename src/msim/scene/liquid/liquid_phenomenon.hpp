#pragma once
// The "liquid" phenomenon: water with a free surface (fluid/liquid, docs/liquid.md) wired to
// scene keys: liquid.*, initial_liquid[], obstacles[].
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType liquidPhenomenonType();

}  // namespace msim::scene
