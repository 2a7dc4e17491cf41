#include "msim/fluid/vortex/vortex_layer.hpp"

#include <algorithm>
#include <stdexcept>

#include "msim/fluid/vortex/vortex_advection.hpp"
#include "msim/fluid/vortex/vortex_force.hpp"
#include "msim/fluid/vortex/vortex_solids.hpp"
#include "msim/fluid/vortex/vortex_stretching.hpp"

namespace msim::fluid {

template <int D>
VortexLayer<D>::VortexLayer(const VortexLayerSettings<D>& settings, const GridSpec<D>& domain, const std::string& context)
    : settings_(settings), domain_(domain), emitter_(settings.seed, domain, settings.rate, settings.randomSeed, context) {
  if (!(settings.start >= 0.0) || !(settings.end > settings.start))
    throw std::invalid_argument(context + ": the seeding window must have 0 <= start < end");
}

template <int D>
void VortexLayer<D>::seedInitial(const Vorticity<D>* flowVorticity) {
  if (settings_.initialCount == 0) return;
  Rng rng(settings_.randomSeed ^ 0x5eedULL);
  seedVortexParticles<D>(particles_, settings_.seed, domain_, settings_.initialCount, rng, flowVorticity);
}

template <int D>
void VortexLayer<D>::addForce(MacGrid<D>& velocity, double dt, const Grid<float, D>* solidMask) const {
  if (!particles_.empty()) addVortexForce<D>(particles_, settings_.kernel, dt, velocity, solidMask);
}

template <int D>
void VortexLayer<D>::advance(const MacGrid<D>& velocity, double dt, double time, const Vorticity<D>* flowVorticity) {
  advectVortexParticles<D>(particles_, velocity, dt);
  stretchVortexParticles<D>(particles_, velocity, dt);
  if (solidPhi_) {
    if (settings_.solids == VortexSolidHandling::Delete)
      removeVortexParticlesInSolid<D>(particles_, *solidPhi_);
    else
      pushVortexParticlesOutOfSolid<D>(particles_, *solidPhi_, 0.5 * domain_.dx);
  }
  removeVortexParticlesOutside<D>(particles_, domain_);
  // The part of the step inside the seeding window.
  const double from = std::max(time, settings_.start), to = std::min(time + dt, settings_.end);
  if (to > from) emitter_.emit(particles_, to - from, flowVorticity);
}

template <int D>
const Vorticity<D>* VortexLayer<D>::flowVorticity(const MacGrid<D>& velocity) {
  if (!needsFlowVorticity()) return nullptr;
  if (!flowVorticity_) flowVorticity_.emplace(velocity.spec());
  computeVorticity(velocity, *flowVorticity_);
  return &*flowVorticity_;
}

template class VortexLayer<2>;
template class VortexLayer<3>;

}  // namespace msim::fluid
