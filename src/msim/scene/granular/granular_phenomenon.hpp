#pragma once
// The "granular" phenomenon: sand and other granular materials with rigid bodies (granular/,
// Narain 2011 ch. 5), wired to the scene keys of granular_scene_keys.hpp. Per frame: particles,
// render points and bodies as PLY, a VDB with phi, pressure, velocity and the particle and body
// state (--resume), and a side-view PNG.
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

PhenomenonType granularPhenomenonType();

}  // namespace msim::scene
