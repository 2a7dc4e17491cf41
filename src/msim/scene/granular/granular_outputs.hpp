#pragma once
// Per-frame files of the "granular" phenomenon: particles, render points and bodies as PLY (for
// renderers), and the VDB with the grid fields (phi, pressure, velocity) plus the full particle
// and body state, which is what --resume reads back.
#include <filesystem>
#include <vector>

#include "msim/granular/granular_simulation.hpp"
#include "msim/io/vdb.hpp"

namespace msim::scene {

// Vertices with vx vy vz mass material (the material's index in materials[]).
void writeParticlePly(const std::filesystem::path& file, const granular::GranularParticles& particles);
// Vertices with the material of each point's particle.
void writeRenderPointPly(const std::filesystem::path& file, const granular::RenderPoints& points,
                         const granular::GranularParticles& particles);
// All of `bodies` (world indices) as one triangle mesh, vertex attribute "body" = scene index.
void writeBodyPly(const std::filesystem::path& file, const rigid::World& world, const std::vector<int>& bodies);

// The frame's grids (phi as a fog volume, pressure, velocity), particles and body states.
void addGranularFrame(io::VdbWriter& writer, const granular::GranularSimulation& sim, const std::vector<int>& bodies);
// Particles and body states from a frame of addGranularFrame; InputError naming `source` and the
// file when something is missing or the body count differs.
void restoreGranularVdb(const std::filesystem::path& file, granular::GranularSimulation& sim,
                        const std::vector<int>& bodies, const std::string& source);

}  // namespace msim::scene
