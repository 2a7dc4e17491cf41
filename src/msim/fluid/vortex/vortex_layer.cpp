#include "msim/fluid/vortex/vortex_layer.hpp"

#include <algorithm>
#include <cmath>
#include <optional>
#include <stdexcept>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/fluid/vortex/velocity_gradient.hpp"
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
  if (split_ && needsFlowVorticity())
    seedVortexParticles<D>(particles_, settings_.seed, domain_, settings_.initialCount, rng, flowAtOwners(flowVorticity));
  else
    seedVortexParticles<D>(particles_, settings_.seed, domain_, settings_.initialCount, rng, flowVorticity);
}

template <int D>
std::size_t VortexLayer<D>::removeWherePositive(const Grid<float, D>& field) {
  if (!split_)  // positive outside: the field taken as minus a signed distance
    return removeVortexParticlesInSolid<D>(particles_, [&](const Vec<D>& x) { return -double(sampleLinear<D>(field, x)); });
  readAtOwners(field.spec(), 1, [&](const Vec<D>& position, std::size_t, double* out) {
    out[0] = sampleLinear<D>(field, position) > 0.0f ? 1.0 : 0.0;
  });
  return particles_.removeIf([&](std::size_t p) { return reads_[p] > 0.0; });
}

template <int D>
FlowVorticitySampler<D> VortexLayer<D>::flowAtOwners(const Vorticity<D>* local) {
  if (!local) throw std::invalid_argument("vortex particles: LocalFlow seeding needs the grid's vorticity");
  return [this, local](const std::vector<Vec<D>>& positions, std::vector<VortexVector<D>>& out) {
    constexpr std::size_t width = VortexVector<D>::RowsAtCompileTime;
    readAt(local->spec(), positions.size(), [&](std::size_t n) { return positions[n]; }, width,
           [&](const Vec<D>& x, std::size_t, double* read) { Eigen::Map<VortexVector<D>>{read} = flowVorticityAt<D>(*local, x); });
    out.resize(positions.size());
    for (std::size_t n = 0; n < positions.size(); ++n) out[n] = Eigen::Map<const VortexVector<D>>(&reads_[n * width]);
  };
}

template <int D>
void VortexLayer<D>::setDomainSplit(DomainSplit<D>* split) {
  split_ = split;
  if (!split) return;
  placement_ = split->placement();
  owned_ = split->owned();
}

template <int D>
void VortexLayer<D>::addForce(MacGrid<D>& velocity, double dt, const Grid<float, D>* solidMask) const {
  if (!particles_.empty()) addVortexForce<D>(particles_, settings_.kernel, dt, velocity, solidMask, placement_);
}

template <int D>
bool VortexLayer<D>::owns(const GridSpec<D>& local, const Vec<D>& x) const {
  for (int a = 0; a < D; ++a) {
    const int global = std::clamp(static_cast<int>(std::floor((x[a] - local.origin[a]) / local.dx)) + placement_.cellOrigin[a],
                                  0, placement_.globalRes[a] - 1);
    const int cell = global - placement_.cellOrigin[a];
    if (cell < owned_.lo[a] || cell >= owned_.hi[a]) return false;
  }
  return true;
}

template <int D>
template <typename PositionOf, typename Read>
void VortexLayer<D>::readAt(const GridSpec<D>& local, std::size_t count, PositionOf&& positionOf, std::size_t width,
                            Read&& read) {
  reads_.assign(count * width, 0.0);
  parallelFor(0, count, [&](std::size_t p) {
    const Vec<D> position = positionOf(p);
    if (owns(local, position)) read(position, p, &reads_[p * width]);
  }, 256);
  split_->sumOverRanks(reads_);
}

template <int D>
template <typename Read>
void VortexLayer<D>::readAtOwners(const GridSpec<D>& local, std::size_t width, Read&& read) {
  const auto& x = particles_.positions();
  readAt(local, x.size(), [&](std::size_t p) { return Vec<D>(x[p].template cast<double>()); }, width,
         std::forward<Read>(read));
}

template <int D>
void VortexLayer<D>::advanceSplit(const MacGrid<D>& velocity, double dt) {
  requireValidVortexTimestep(dt, "VortexLayer::advance");
  auto& x = particles_.positions();
  const GridSpec<D>& local = velocity.spec();
  // Advection (advectVortexParticles): each particle's displacement.
  readAtOwners(local, D, [&](const Vec<D>& position, std::size_t, double* out) {
    Eigen::Map<Vec<D>>{out} = dt * sampleLinear<D>(velocity, position);
  });
  parallelFor(0, x.size(), [&](std::size_t p) {
    x[p] = (x[p].template cast<double>() + Eigen::Map<const Vec<D>>(&reads_[p * D])).template cast<float>();
  }, 256);
  // Stretching (stretchVortexParticles) at the new places.
  if constexpr (D == 3) {
    auto& omega = particles_.vorticities();
    readAtOwners(local, 3, [&](const Vec<3>& position, std::size_t p, double* out) {
      Eigen::Map<Eigen::Vector3d>{out} = stretchAndRescale(omega[p], velocityGradientAt<3>(velocity, position), dt);
    });
    parallelFor(0, x.size(), [&](std::size_t p) { omega[p] = Eigen::Map<const Eigen::Vector3d>(&reads_[p * 3]); }, 256);
  }
  // Solids (vortex_solids.hpp): whether a particle stays (1) and where it goes.
  if (solidPhi_) {
    const auto phi = [&](const Vec<D>& y) { return double(sampleLinear<D>(*solidPhi_, y)); };
    const bool push = settings_.solids == VortexSolidHandling::PushOut;
    readAtOwners(local, D + 1, [&](const Vec<D>& position, std::size_t, double* out) {
      std::optional<Vec<D>> kept = position;
      if (phi(position) < 0.0)
        kept = push ? pushedOutOfSolid<D>(phi, position, 0.5 * solidPhi_->spec().dx, 0.5 * domain_.dx) : std::nullopt;
      if (!kept) return;
      out[0] = 1.0;
      Eigen::Map<Vec<D>>{out + 1} = *kept;
    });
    // The predicate moves a survivor before removeIf moves it down (as pushVortexParticlesOutOfSolid).
    particles_.removeIf([&](std::size_t p) {
      if (!(reads_[p * (D + 1)] > 0.0)) return true;
      x[p] = Eigen::Map<const Vec<D>>(&reads_[p * (D + 1) + 1]).template cast<float>();
      return false;
    });
  }
}

template <int D>
void VortexLayer<D>::advance(const MacGrid<D>& velocity, double dt, double time, const Vorticity<D>* flowVorticity) {
  if (split_) {
    advanceSplit(velocity, dt);
  } else {
    advectVortexParticles<D>(particles_, velocity, dt);
    stretchVortexParticles<D>(particles_, velocity, dt);
    if (solidPhi_) {
      if (settings_.solids == VortexSolidHandling::Delete)
        removeVortexParticlesInSolid<D>(particles_, *solidPhi_);
      else
        pushVortexParticlesOutOfSolid<D>(particles_, *solidPhi_, 0.5 * domain_.dx);
    }
  }
  removeVortexParticlesOutside<D>(particles_, domain_);
  // The part of the step inside the seeding window.
  const double from = std::max(time, settings_.start), to = std::min(time + dt, settings_.end);
  if (!(to > from)) return;
  if (split_ && needsFlowVorticity())
    emitter_.emit(particles_, to - from, flowAtOwners(flowVorticity));
  else
    emitter_.emit(particles_, to - from, flowVorticity);
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
