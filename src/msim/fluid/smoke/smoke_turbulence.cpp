#include "msim/fluid/smoke/smoke_turbulence.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "msim/core/resample.hpp"
#include "msim/core/parallel.hpp"

namespace msim::fluid {

template <int D>
SmokeTurbulence<D>::SmokeTurbulence(const GridSpec<D>& coarse, const SmokeTurbulenceParams& params,
                                    const numerics::AdvectionSettings& advection, const Grid<float, D>* coarseSolid,
                                    double ambientTemperature)
    : params_(params),
      ambientTemperature_(ambientTemperature),
      model_(coarse, params, advection, coarseSolid),
      density_(model_.fineSpec(), 0.0f),
      temperature_(model_.fineSpec(), static_cast<float>(ambientTemperature)),
      coarseTurbulent_(coarse) {}

template <int D>
void SmokeTurbulence<D>::setSolid(const Grid<float, D>& coarseSolid) {
  model_.setSolid(coarseSolid);
  clearSmokeInSolids();
}

template <int D>
void SmokeTurbulence<D>::clearSmokeInSolids() {
  const Grid<float, D>& solid = model_.fineSolid();
  parallelFor(0, density_.count(), [&](std::size_t i) {
    if (solid[i] > 0.5f) density_[i] = 0.0f;
  }, 1 << 14);
}

template <int D>
void SmokeTurbulence<D>::markSeeds(const Grid<float, D>& coarseDensity, const Grid<float, D>& coarseTemperature) {
  constexpr double kHeatTolerance = 0.01;  // [K] warmer or cooler than ambient: heat the flow carries
  seeds_.resize(coarseDensity.count());
  parallelFor(0, seeds_.size(), [&](std::size_t i) {
    seeds_[i] = coarseDensity[i] > params_.smokeThreshold ||
                std::abs(coarseTemperature[i] - ambientTemperature_) > kHeatTolerance;
  }, 4096);
}

template <int D>
void SmokeTurbulence<D>::addSource(SmokeSource<D> source) {
  if (!source.scalars.empty())
    throw std::invalid_argument("SmokeTurbulence: fine-grid sources carry density and temperature only");
  sources_.push_back(std::move(source));
}

template <int D>
void SmokeTurbulence<D>::applySources(double dt, Grid<float, D>& coarseDensity, Grid<float, D>& coarseTemperature) {
  // addSource refused extra scalars, so the accessor is never called.
  auto noScalars = [&](std::size_t) -> Grid<float, D>& { throw std::logic_error("SmokeTurbulence: no extra scalars"); };
  for (const auto& src : sources_) applySourceScalars<D>(src, dt, density_, temperature_, noScalars);
  downsample(coarseDensity, coarseTemperature);
}

template <int D>
void SmokeTurbulence<D>::downsample(Grid<float, D>& coarseDensity, Grid<float, D>& coarseTemperature) const {
  const int r = params_.refinement;
  blockAverage<D>(density_, coarseDensity, r, IVec<D>::Constant(r));
  blockAverage<D>(temperature_, coarseTemperature, r, IVec<D>::Constant(r));
}

template <int D>
void SmokeTurbulence<D>::averageTurbulenceToCoarse() {
  // The coarse face's flux is the mean of the fine faces that tile it (r^(D-1) of them), so each
  // coarse cell's net flux is the sum of its fine cells' (zero) divergences.
  const int r = params_.refinement;
  for (int a = 0; a < D; ++a) {
    IVec<D> block = IVec<D>::Constant(r);
    block[a] = 1;
    blockAverage<D>(model_.turbulentVelocity().component(a), coarseTurbulent_.component(a), r, block);
  }
}

template <int D>
void SmokeTurbulence<D>::step(const MacGrid<D>& velocity, double dt, Grid<float, D>& coarseDensity,
                              Grid<float, D>& coarseTemperature) {
  model_.stepEnergy(velocity, dt);
  markSeeds(coarseDensity, coarseTemperature);
  model_.synthesize(velocity, dt, seeds_);
  // The fine scalars in a box round the band (fainter smoke outside it stays where it is).
  model_.advect({&density_, &temperature_}, velocity, dt);
  dissipateSmoke<D>(density_, temperature_, params_.densityDissipation, params_.temperatureDissipation,
                    ambientTemperature_, dt);
  downsample(coarseDensity, coarseTemperature);
  averageTurbulenceToCoarse();
}

template <int D>
double SmokeTurbulence<D>::turbulentKineticEnergy() const {
  // Each face carries one velocity component over about one cell's volume.
  double sum = 0.0;
  for (int a = 0; a < D; ++a) {
    const auto& u = model_.turbulentVelocity().component(a);
    sum += parallelSum(u.count(), [&](std::size_t i) { return double(u[i]) * u[i]; });
  }
  return 0.5 * sum * model_.fineSpec().cellVolume();
}

template class SmokeTurbulence<2>;
template class SmokeTurbulence<3>;

}  // namespace msim::fluid
