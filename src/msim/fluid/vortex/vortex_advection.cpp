#include "msim/fluid/vortex/vortex_advection.hpp"

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"

namespace msim::fluid {

template <int D>
void advectVortexParticles(VortexParticles<D>& particles, const MacGrid<D>& velocity, double dt) {
  requireValidVortexTimestep(dt, "advectVortexParticles");
  auto& x = particles.positions();
  parallelFor(0, x.size(), [&](std::size_t p) {
    const Vec<D> position = x[p].template cast<double>();
    x[p] = (position + dt * sampleLinear<D>(velocity, position)).template cast<float>();
  }, 256);
}

template <int D>
std::size_t removeVortexParticlesOutside(VortexParticles<D>& particles, const GridSpec<D>& domain) {
  const auto& x = particles.positions();
  return particles.removeIf([&](std::size_t p) { return !domain.contains(x[p].template cast<double>()); });
}

template void advectVortexParticles<2>(VortexParticles<2>&, const MacGrid<2>&, double);
template void advectVortexParticles<3>(VortexParticles<3>&, const MacGrid<3>&, double);
template std::size_t removeVortexParticlesOutside<2>(VortexParticles<2>&, const GridSpec<2>&);
template std::size_t removeVortexParticlesOutside<3>(VortexParticles<3>&, const GridSpec<3>&);

}  // namespace msim::fluid
