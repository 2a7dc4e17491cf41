#include "msim/fluid/smoke/smoke_turbulence.hpp"

#include <algorithm>
#include <array>
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
  // Each coarse cell's distance (in cells, the maximum over the axes) to the cells with smoke or
  // heat, by one pass per axis: d_a(c) = min_k max(|k|, d_(a-1)(c + k e_a)), counted up to `far`.
  // The core, within `reach` of them (one cell and the distance the fastest face covers in a
  // step), gets the full u'; the potential then falls linearly to zero over kTaper more cells, so
  // the band's edge makes no sheet of velocity (cutting psi off from one fine node to the next
  // would put about twice the eddies' speed on it).
  const double fastest = maxFaceSpeed(velocity);
  constexpr int kTaper = 2;
  const int reach = std::min(200, 1 + static_cast<int>(std::ceil(fastest * dt / coarse_.dx)));
  const int far = reach + kTaper;
  const std::size_t cells = coarseDensity.count();
  coarseLevel_.resize(cells);
  constexpr double kHeatTolerance = 0.01;  // [K] warmer or cooler than ambient: heat the flow carries
  parallelFor(0, cells, [&](std::size_t i) {
    const bool source = coarseDensity[i] > params_.smokeThreshold ||
                        std::abs(coarseTemperature[i] - ambientTemperature_) > kHeatTolerance;
    coarseLevel_[i] = static_cast<std::uint8_t>(source ? 0 : far + 1);
  }, 4096);
  std::vector<std::uint8_t>& next = levelScratch_;
  next.resize(cells);
  for (int a = 0; a < D; ++a) {
    parallelForCells<D>(coarse_.res, [&](const IVec<D>& c, std::size_t lin) {
      int level = coarseLevel_[lin];
      for (int k = 1; k <= far && k < level; ++k)
        for (const int n : {c[a] - k, c[a] + k}) {
          if (n < 0 || n >= coarse_.res[a]) continue;
          const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(n - c[a]) * static_cast<std::ptrdiff_t>(coarseDensity.stride(a));
          level = std::min(level, std::max(k, int(coarseLevel_[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(lin) + offset)])));
        }
      next[lin] = static_cast<std::uint8_t>(level);
    });
    coarseLevel_.swap(next);
  }
  // The core's bounding box, rounded out to whole blocks of kBoxBlock cells so the advection window
  // changes only every few steps as the smoke spreads.
  constexpr int kBoxBlock = 4;
  IVec<D> lo = coarse_.res, hi = IVec<D>::Zero();
  for (std::size_t i = 0; i < cells; ++i) {
    if (coarseLevel_[i] > reach) continue;
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
  // The weight at the coarse nodes: 1 at the corners of core cells, falling by 1 / kTaper per cell
  // beyond; at the fine nodes, interpolated multilinearly from them.
  const IVec<D> coarseNodes = coarse_.res + IVec<D>::Ones();
  std::size_t coarseNodeCount = 1;
  for (int d = 0; d < D; ++d) coarseNodeCount *= static_cast<std::size_t>(coarseNodes[d]);
  coarseNodeWeight_.resize(coarseNodeCount);
  parallelForCells<D>(coarseNodes, [&](const IVec<D>& node, std::size_t n) {
    int level = far + 1;
    for (int corner = 0; corner < (1 << D); ++corner) {
      IVec<D> c = node;
      bool inside = true;
      for (int d = 0; d < D; ++d) {
        c[d] -= (corner >> d) & 1;
        inside = inside && c[d] >= 0 && c[d] < coarse_.res[d];
      }
      if (inside) level = std::min(level, int(coarseLevel_[coarseDensity.index(c)]));
    }
    coarseNodeWeight_[n] = std::clamp(1.0f - static_cast<float>(level - reach) / kTaper, 0.0f, 1.0f);
  });
  const IVec<D> nodes = fine_.res + IVec<D>::Ones();
  std::size_t nodeCount = 1, rows = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(nodes[d]);
  nodeWeight_.resize(nodeCount);
  const int r = params_.refinement;
  const float invR = 1.0f / static_cast<float>(r);
  auto tap = [&](int fineIndex, int coarseCount) {  // coarse node below, its fraction; the stride is the caller's
    const int below = std::min(fineIndex / r, coarseCount - 2);
    return std::pair<int, float>(below, static_cast<float>(fineIndex - below * r) * invR);
  };
  const double marked = parallelSum(rows, [&](std::size_t row) {
    // The coarse node rows bracketing this fine row, blended across the other axes.
    thread_local std::vector<float> blended;
    blended.assign(static_cast<std::size_t>(coarseNodes[0]), 0.0f);
    std::array<std::pair<int, float>, D> across{};
    std::size_t rest = row;
    for (int d = 1; d < D; ++d) {
      across[d] = tap(static_cast<int>(rest % static_cast<std::size_t>(nodes[d])), coarseNodes[d]);
      rest /= static_cast<std::size_t>(nodes[d]);
    }
    bool any = false;
    for (int corner = 0; corner < (1 << (D - 1)); ++corner) {
      float w = 1.0f;
      std::size_t offset = 0, stride = static_cast<std::size_t>(coarseNodes[0]);
      for (int d = 1; d < D; ++d) {
        const bool up = (corner >> (d - 1)) & 1;
        w *= up ? across[d].second : 1.0f - across[d].second;
        offset += static_cast<std::size_t>(across[d].first + up) * stride;
        stride *= static_cast<std::size_t>(coarseNodes[d]);
      }
      if (w == 0.0f) continue;
      const float* source = coarseNodeWeight_.data() + offset;
      for (int x = 0; x < coarseNodes[0]; ++x) {
        blended[static_cast<std::size_t>(x)] += w * source[x];
        any = any || source[x] > 0.0f;
      }
    }
    float* weight = nodeWeight_.data() + row * static_cast<std::size_t>(nodes[0]);
    if (!any) {
      std::fill(weight, weight + nodes[0], 0.0f);
      return 0.0;
    }
    int count = 0;
    for (int x = 0; x < nodes[0]; ++x) {
      const auto [below, f] = tap(x, coarseNodes[0]);
      weight[x] = blended[static_cast<std::size_t>(below)] + f * (blended[static_cast<std::size_t>(below) + 1] - blended[static_cast<std::size_t>(below)]);
      count += weight[x] > 0.0f;
    }
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
    blockAverage<D>(turbulent_.component(a), coarseTurbulent_.component(a), r, block);
  }
}

template <int D>
void SmokeTurbulence<D>::step(const MacGrid<D>& velocity, double dt, Grid<float, D>& coarseDensity,
                              Grid<float, D>& coarseTemperature) {
  energy_.step(velocity, dt);
  particles_->advance(velocity, energy_, dt);
  markBand(velocity, dt, coarseDensity, coarseTemperature);
  particles_->synthesize(energy_, turbulent_, &nodeWeight_);
  advectScalars(velocity, dt);
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
    const auto& u = turbulent_.component(a);
    sum += parallelSum(u.count(), [&](std::size_t i) { return double(u[i]) * u[i]; });
  }
  return 0.5 * sum * fine_.cellVolume();
}

template class SmokeTurbulence<2>;
template class SmokeTurbulence<3>;

}  // namespace msim::fluid
