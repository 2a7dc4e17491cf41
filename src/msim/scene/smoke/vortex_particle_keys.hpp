#pragma once
// The scene keys of vortex particles in smoke (smoke.vortex_particles.*, Selle ch. 3.3-3.5;
// fluid/vortex) and the layer they build.
#include <memory>

#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

Schema vortexParticleKeys();

// The layer of smoke.vortex_particles, or null when it is off. InputError naming the key for a
// seeding region outside the domain or inverted, a non-positive radius, a negative strength, rate
// or magnitude, an empty seeding window, or an up axis the scene lacks.
template <int D>
std::unique_ptr<fluid::VortexLayer<D>> vortexLayer(const Scene& scene);

}  // namespace msim::scene
