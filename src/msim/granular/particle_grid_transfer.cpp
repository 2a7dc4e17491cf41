#include "msim/granular/particle_grid_transfer.hpp"

#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"

namespace msim::granular {

ParticleGridFields::ParticleGridFields(const GridSpec<3>& spec)
    : mass(spec), volume(spec), friction(spec), momentum(spec), faceMass(spec), faceVolume(spec), velocity(spec) {}

void ParticleGridTransfer::toGrid(const GranularParticles& particles, std::span<const GranularMaterial> materials,
                                  ParticleGridFields& out) {
  const std::size_t n = particles.size();
  const double highestMaterial = parallelMax(n, [&](std::size_t i) { return particles.material[i]; });
  if (n > 0 && highestMaterial >= static_cast<double>(materials.size()))
    throw std::invalid_argument("granular transfer: particle material index " +
                                std::to_string(static_cast<int>(highestMaterial)) + " outside the table of " +
                                std::to_string(materials.size()) + " materials");

  volume_.resize(n);
  volumeFriction_.resize(n);
  for (std::vector<float>& m : momentum_) m.resize(n);
  parallelFor(0, n, [&](std::size_t i) {
    const GranularMaterial& material = materials[particles.material[i]];
    const double v = particles.mass[i] / material.density;
    volume_[i] = static_cast<float>(v);
    volumeFriction_[i] = static_cast<float>(v * material.friction);
    const Vecf<3> momentum = particles.mass[i] * particles.velocity[i];
    for (int a = 0; a < 3; ++a) momentum_[a][i] = momentum[a];
  });

  // Each grid layout in one pass: the cell centres, then the faces of each axis.
  const std::span<const Vecf<3>> x = particles.position;
  constexpr auto kLinear = TransferKernel::Linear;
  out.mass.fill(0.0f);
  out.volume.fill(0.0f);
  out.friction.fill(0.0f);
  out.momentum.fill(0.0f);
  out.faceMass.fill(0.0f);
  out.faceVolume.fill(0.0f);
  splatter_.splatSums<3>(x, {particles.mass, volume_, volumeFriction_},  // sum w V alpha, normalised below
                         {&out.mass, &out.volume, &out.friction}, kLinear);
  for (int a = 0; a < 3; ++a)
    splatter_.splatSums<3>(x, {momentum_[a], particles.mass, volume_},
                           {&out.momentum.component(a), &out.faceMass.component(a), &out.faceVolume.component(a)},
                           kLinear);

  parallelFor(0, out.friction.count(), [&](std::size_t c) {
    const float v = out.volume[c];
    out.friction[c] = v > 0.0f ? out.friction[c] / v : 0.0f;
  }, 1 << 14);
  for (int a = 0; a < 3; ++a) {
    const Grid<float, 3>& p = out.momentum.component(a);
    const Grid<float, 3>& m = out.faceMass.component(a);
    Grid<float, 3>& u = out.velocity.component(a);
    parallelFor(0, u.count(), [&](std::size_t f) { u[f] = m[f] > 0.0f ? p[f] / m[f] : 0.0f; }, 1 << 14);
  }
}

void ParticleGridTransfer::toParticles(const MacGrid<3>& oldVelocity, const MacGrid<3>& newVelocity,
                                       GranularParticles& particles, double flipRatio) {
  if (!(flipRatio >= 0.0 && flipRatio <= 1.0))
    throw std::invalid_argument("granular transfer: FLIP ratio must lie in [0, 1], got " + std::to_string(flipRatio));
  const std::size_t n = particles.size();
  oldAt_.resize(n);
  newAt_.resize(n);
  gather<3, 2>({&oldVelocity, &newVelocity}, particles.position, TransferKernel::Linear, {oldAt_, newAt_});
  const float flip = static_cast<float>(flipRatio);
  parallelFor(0, n, [&](std::size_t i) {
    const Vecf<3> flipped = particles.velocity[i] + (newAt_[i] - oldAt_[i]);
    particles.velocity[i] = flip * flipped + (1.0f - flip) * newAt_[i];
  });
}

}  // namespace msim::granular
