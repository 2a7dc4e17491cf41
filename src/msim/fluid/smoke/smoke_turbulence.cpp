#include "msim/fluid/smoke/smoke_turbulence.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "msim/core/grid_window.hpp"
#include "msim/core/resample.hpp"
#include "msim/core/parallel.hpp"

namespace msim::fluid {

namespace {

template <int D>
GridSpec<D> refined(const GridSpec<D>& coarse, int r) {
  if (r < 1) throw std::invalid_argument("SmokeTurbulence: the refinement must be >= 1");
  return GridSpec<D>(coarse.origin, coarse.dx / r, coarse.res * r);
}

}  // namespace

template <int D>
SmokeTurbulence<D>::SmokeTurbulence(const GridSpec<D>& coarse, const SmokeTurbulenceParams& params,
                                    const numerics::AdvectionSettings& advection, const Grid<float, D>* coarseSolid,
                                    double ambientTemperature)
    : coarse_(coarse),
      fine_(refined(coarse, params.refinement)),
      params_(params),
      advection_(advection),
      ambientTemperature_(ambientTemperature),
      coarseSolid_(coarse, 0.0f),
      fineSolid_(fine_, 0.0f),
      density_(fine_, 0.0f),
      temperature_(fine_, static_cast<float>(ambientTemperature)),
      turbulent_(fine_),
      coarseTurbulent_(coarse),
      energy_(coarse, params.energy) {
  if (coarseSolid) applySolid(*coarseSolid);
  reseedParticles();
}

template <int D>
void SmokeTurbulence<D>::applySolid(const Grid<float, D>& coarseSolid) {
  coarseSolid_ = coarseSolid;
  hasSolid_ = true;
  const int r = params_.refinement;
  parallelForCells<D>(fine_.res, [&](const IVec<D>& c, std::size_t lin) { fineSolid_[lin] = coarseSolid_(IVec<D>(c / r)); });
  energy_.setSolid(coarseSolid_);
  windowSolidStale_ = true;
  // Smoke does not live inside solids.
  parallelFor(0, density_.count(), [&](std::size_t i) {
    if (fineSolid_[i] > 0.5f) density_[i] = 0.0f;
  }, 1 << 14);
}

template <int D>
void SmokeTurbulence<D>::setSolid(const Grid<float, D>& coarseSolid) {
  applySolid(coarseSolid);
  if (particles_) particles_->setSolid(coarseSolid_);
}

template <int D>
void SmokeTurbulence<D>::reseedParticles() {
  particles_ = std::make_unique<turbulence::NoiseParticles<D>>(coarse_, energy_, fine_.dx, params_.particles,
                                                                hasSolid_ ? &coarseSolid_ : nullptr);
}

template <int D>
void SmokeTurbulence<D>::markBand(const MacGrid<D>& velocity, double dt, const Grid<float, D>& coarseDensity,
                                  const Grid<float, D>& coarseTemperature) {
  // Coarse cells with smoke or heat, grown by one cell and by the cells the fastest face crosses in
  // a step.
  double fastest = 0.0;
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity.component(a);
    fastest = std::max(fastest, parallelMax(u.count(), [&](std::size_t i) { return std::abs(u[i]); }));
  }
  const int grow = 1 + static_cast<int>(std::ceil(fastest * dt / coarse_.dx));
  const std::size_t cells = coarseDensity.count();
  coarseBand_.assign(cells, 0);
  constexpr double kHeatTolerance = 0.01;  // [K] warmer or cooler than ambient: heat the flow carries
  parallelFor(0, cells, [&](std::size_t i) {
    coarseBand_[i] = coarseDensity[i] > params_.smokeThreshold ||
                     std::abs(coarseTemperature[i] - ambientTemperature_) > kHeatTolerance;
  }, 4096);
  std::vector<std::uint8_t>& next = bandScratch_;
  next.resize(cells);
  for (int a = 0; a < D; ++a) {
    parallelForCells<D>(coarse_.res, [&](const IVec<D>& c, std::size_t lin) {
      std::uint8_t any = 0;
      for (int k = -grow; k <= grow && !any; ++k) {
        IVec<D> n = c;
        n[a] += k;
        if (n[a] < 0 || n[a] >= coarse_.res[a]) continue;
        any = coarseBand_[static_cast<std::size_t>(lin + static_cast<std::ptrdiff_t>(k) * static_cast<std::ptrdiff_t>(coarseDensity.stride(a)))];
      }
      next[lin] = any;
    });
    coarseBand_.swap(next);
  }
  // Their bounding box, rounded out to whole blocks of kBoxBlock cells so the advection window
  // changes only every few steps as the smoke spreads.
  constexpr int kBoxBlock = 4;
  IVec<D> lo = coarse_.res, hi = IVec<D>::Zero();
  for (std::size_t i = 0; i < cells; ++i) {
    if (!coarseBand_[i]) continue;
    const IVec<D> c = coarseDensity.coord(i);
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c + IVec<D>::Ones());
  }
  bandLo_ = bandHi_ = IVec<D>::Zero();
  if ((hi.array() > lo.array()).all()) {
    for (int d = 0; d < D; ++d) {
      bandLo_[d] = lo[d] / kBoxBlock * kBoxBlock;
      bandHi_[d] = std::min(coarse_.res[d], (hi[d] + kBoxBlock - 1) / kBoxBlock * kBoxBlock);
    }
  }
  // Fine nodes of the marked coarse cells (a node belongs to the cell it is the lower corner of,
  // clamped at the upper walls).
  const IVec<D> nodes = fine_.res + IVec<D>::Ones();
  std::size_t nodeCount = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  nodeMask_.resize(nodeCount);
  const int r = params_.refinement;
  std::size_t rows = 1;
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(nodes[d]);
  const double marked = parallelSum(rows, [&](std::size_t row) {
    std::size_t coarseRow = 0, rest = row, coarseStride = 1;
    for (int d = 1; d < D; ++d) {
      const int n = static_cast<int>(rest % static_cast<std::size_t>(nodes[d]));
      rest /= static_cast<std::size_t>(nodes[d]);
      coarseStride *= static_cast<std::size_t>(coarse_.res[d - 1]);
      coarseRow += static_cast<std::size_t>(std::min(n / r, coarse_.res[d] - 1)) * coarseStride;
    }
    const std::uint8_t* band = coarseBand_.data() + coarseRow;
    std::uint8_t* mask = nodeMask_.data() + row * static_cast<std::size_t>(nodes[0]);
    int count = 0;
    for (int x = 0; x < nodes[0]; ++x) count += mask[x] = band[std::min(x / r, coarse_.res[0] - 1)];
    return double(count);
  });
  bandFraction_ = marked / static_cast<double>(nodeCount);
}

template <int D>
SmokeTurbulence<D>::Window::Window(const GridSpec<D>& fine, const IVec<D>& lo, const IVec<D>& size,
                                   const numerics::AdvectionSettings& advection)
    : lo(lo),
      size(size),
      density(GridSpec<D>(fine.origin + lo.template cast<double>() * fine.dx, fine.dx, size)),
      temperature(density.spec()),
      velocity(density.spec()),
      advector(density.spec(), advection) {}

template <int D>
void SmokeTurbulence<D>::advectScalars(const MacGrid<D>& velocity, double dt) {
  if (bandHi_ == bandLo_) return;  // no smoke or heat anywhere
  const int r = params_.refinement;
  const IVec<D> lo = bandLo_ * r, size = (bandHi_ - bandLo_) * r;
  if (!window_ || window_->lo != lo || window_->size != size) {
    window_.reset();
    window_.emplace(fine_, lo, size, advection_);
    windowSolidStale_ = hasSolid_;
  }
  Window& w = *window_;
  auto copyIn = [](const float* big, float* window, std::size_t n) { std::copy(big, big + n, window); };
  auto copyOut = [](float* big, const float* window, std::size_t n) { std::copy(window, window + n, big); };
  if (windowSolidStale_) {
    Grid<float, D> solid(w.density.spec());
    forEachWindowRow<D>(std::as_const(fineSolid_), lo, solid, copyIn);
    w.advector.setSolid(solid);
    windowSolidStale_ = false;
  }
  forEachWindowRow<D>(std::as_const(density_), lo, w.density, copyIn);
  forEachWindowRow<D>(std::as_const(temperature_), lo, w.temperature, copyIn);
  advectingVelocity(velocity, lo, w.velocity);
  w.advector.advect(w.density, w.velocity, dt);
  w.advector.advect(w.temperature, w.velocity, dt);
  forEachWindowRow<D>(density_, lo, std::as_const(w.density), copyOut);
  forEachWindowRow<D>(temperature_, lo, std::as_const(w.temperature), copyOut);
}

template <int D>
void SmokeTurbulence<D>::advectingVelocity(const MacGrid<D>& velocity, const IVec<D>& lo, MacGrid<D>& out) const {
  auto addIn = [](const float* big, float* window, std::size_t n) {
    for (std::size_t i = 0; i < n; ++i) window[i] += big[i];
  };
  for (int a = 0; a < D; ++a) {
    resampleLinear<D>(velocity.component(a), out.component(a));
    forEachWindowRow<D>(turbulent_.component(a), lo, out.component(a), addIn);
  }
}

template <int D>
MacGrid<D> SmokeTurbulence<D>::fineVelocity(const MacGrid<D>& velocity) const {
  MacGrid<D> out(fine_);
  advectingVelocity(velocity, IVec<D>::Zero(), out);
  return out;
}

template <int D>
void SmokeTurbulence<D>::addSource(SmokeSource<D> source) {
  if (!source.scalars.empty())
    throw std::invalid_argument("SmokeTurbulence: fine-grid sources carry density and temperature only");
  sources_.push_back(std::move(source));
}

template <int D>
void SmokeTurbulence<D>::applySources(double dt) {
  // addSource refused extra scalars, so the accessor is never called.
  auto noScalars = [&](std::size_t) -> Grid<float, D>& { throw std::logic_error("SmokeTurbulence: no extra scalars"); };
  for (const auto& src : sources_) applySourceScalars<D>(src, dt, density_, temperature_, noScalars);
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
    blockAverage<D>(turbulent_.component(a), coarseTurbulent_.component(a), r, block);
  }
}

template <int D>
void SmokeTurbulence<D>::step(const MacGrid<D>& velocity, double dt, Grid<float, D>& coarseDensity,
                              Grid<float, D>& coarseTemperature) {
  energy_.step(velocity, dt);
  particles_->advance(velocity, energy_, dt);
  applySources(dt);
  downsample(coarseDensity, coarseTemperature);  // the band sees this step's sources
  markBand(velocity, dt, coarseDensity, coarseTemperature);
  particles_->synthesize(energy_, turbulent_, &nodeMask_);
  advectScalars(velocity, dt);
  downsample(coarseDensity, coarseTemperature);
  averageTurbulenceToCoarse();
}

template <int D>
double SmokeTurbulence<D>::turbulentKineticEnergy() const {
  // Each face carries one velocity component over about one cell's volume.
  double sum = 0.0;
  for (int a = 0; a < D; ++a) {
    const auto& u = turbulent_.component(a);
    sum += parallelSum(u.count(), [&](std::size_t i) { return double(u[i]) * u[i]; });
  }
  return 0.5 * sum * fine_.cellVolume();
}

template class SmokeTurbulence<2>;
template class SmokeTurbulence<3>;

}  // namespace msim::fluid
