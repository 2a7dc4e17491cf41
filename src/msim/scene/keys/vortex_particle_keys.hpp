#pragma once
// The scene keys of vortex particles (smoke.vortex_particles.*, liquid.vortex_particles.*; Selle
// ch. 3.3-3.5, fluid/vortex), the layer they build, and the particles in a frame's files (VDB
// points and PLY with their vorticity wx, wy, wz) and back (--resume).
#include <memory>
#include <string>

#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

Schema vortexParticleKeys();

// The layer of <phenomenon>.vortex_particles, or null when it is off. InputError naming the key for a
// seeding region outside the domain or inverted, a non-positive radius, a negative strength, rate
// or magnitude, an empty seeding window, or an up axis the scene lacks.
template <int D>
std::unique_ptr<fluid::VortexLayer<D>> vortexLayer(const Scene& scene, const std::string& phenomenon);

// The particles as points with their vorticity wx, wy, wz (2D: wz only, the others 0).
template <int D>
io::PointCloud vortexParticleCloud(const fluid::VortexParticles<D>& particles);

// The particles of a saved frame's points `name`, with the layer's radius and strength (the
// emitter restarts: a resumed run seeds the same count, not the same particles). InputError naming
// `source` and the file when an attribute is missing.
template <int D>
void restoreVortexParticles(const io::VdbFile& saved, const std::string& name, fluid::VortexLayer<D>& layer,
                            const std::string& source);

}  // namespace msim::scene
