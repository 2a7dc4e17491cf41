#include "msim/fluid/smoke/smoke_turbulence.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

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
      coarseSolid_(coarse, 0.0f),
      fineSolid_(fine_, 0.0f),
      density_(fine_, 0.0f),
      temperature_(fine_, static_cast<float>(ambientTemperature)),
      turbulent_(fine_),
      advecting_(fine_),
      coarseTurbulent_(coarse),
      energy_(coarse, params.energy),
      advector_(fine_, advection) {
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
  advector_.setSolid(fineSolid_);
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
void SmokeTurbulence<D>::markBand(const MacGrid<D>& velocity, double dt, const Grid<float, D>& coarseDensity) {
  // Coarse cells with smoke, grown by one cell and by the cells the fastest face crosses in a step.
  double fastest = 0.0;
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity.component(a);
    fastest = std::max(fastest, parallelMax(u.count(), [&](std::size_t i) { return std::abs(u[i]); }));
  }
  const int grow = 1 + static_cast<int>(std::ceil(fastest * dt / coarse_.dx));
  const std::size_t cells = coarseDensity.count();
  coarseBand_.assign(cells, 0);
  parallelFor(0, cells, [&](std::size_t i) { coarseBand_[i] = coarseDensity[i] > params_.smokeThreshold ? 1 : 0; }, 4096);
  std::vector<std::uint8_t> next(cells);
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
  // Fine nodes of the marked coarse cells (a node belongs to the cell it is the lower corner of,
  // clamped at the upper walls).
  const IVec<D> nodes = fine_.res + IVec<D>::Ones();
  std::size_t nodeCount = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  nodeMask_.assign(nodeCount, 0);
  const int r = params_.refinement;
  const double marked = parallelSum(nodeCount, [&](std::size_t a) {
    std::size_t rest = a, cell = 0, stride = 1;
    for (int d = 0; d < D; ++d) {
      const int n = static_cast<int>(rest % nodes[d]);
      rest /= nodes[d];
      cell += static_cast<std::size_t>(std::min(n / r, coarse_.res[d] - 1)) * stride;
      stride *= static_cast<std::size_t>(coarse_.res[d]);
    }
    nodeMask_[a] = coarseBand_[cell];
    return double(nodeMask_[a]);
  });
  bandFraction_ = marked / static_cast<double>(nodeCount);
}

template <int D>
void SmokeTurbulence<D>::updateAdvectingVelocity(const MacGrid<D>& velocity) {
  for (int a = 0; a < D; ++a) {
    auto& w = advecting_.component(a);
    const auto& t = turbulent_.component(a);
    resampleLinear<D>(velocity.component(a), w);
    parallelFor(0, w.count(), [&](std::size_t i) { w[i] += t[i]; }, 1 << 14);
  }
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
  int children = 1;
  for (int d = 0; d < D; ++d) children *= r;
  parallelForCells<D>(coarse_.res, [&](const IVec<D>& c, std::size_t lin) {
    double rho = 0.0, temp = 0.0;
    for (int k = 0; k < children; ++k) {
      IVec<D> f = c * r;
      int rest = k;
      for (int d = 0; d < D; ++d) {
        f[d] += rest % r;
        rest /= r;
      }
      rho += density_(f);
      temp += temperature_(f);
    }
    coarseDensity[lin] = static_cast<float>(rho / children);
    coarseTemperature[lin] = static_cast<float>(temp / children);
  });
}

template <int D>
void SmokeTurbulence<D>::averageTurbulenceToCoarse() {
  // The coarse face's flux is the mean of the fine faces that tile it (r^(D-1) of them), so each
  // coarse cell's net flux is the sum of its fine cells' (zero) divergences.
  const int r = params_.refinement;
  int faces = 1;
  for (int d = 0; d < D - 1; ++d) faces *= r;
  for (int a = 0; a < D; ++a) {
    auto& coarse = coarseTurbulent_.component(a);
    const auto& fine = turbulent_.component(a);
    parallelForCells<D>(coarse.size(), [&](const IVec<D>& c, std::size_t lin) {
      double sum = 0.0;
      for (int k = 0; k < faces; ++k) {
        IVec<D> f = c * r;
        int rest = k;
        for (int d = 0; d < D; ++d) {
          if (d == a) continue;
          f[d] += rest % r;
          rest /= r;
        }
        sum += fine(f);
      }
      coarse[lin] = static_cast<float>(sum / faces);
    });
  }
}

template <int D>
void SmokeTurbulence<D>::step(const MacGrid<D>& velocity, double dt, Grid<float, D>& coarseDensity,
                              Grid<float, D>& coarseTemperature) {
  energy_.step(velocity, dt);
  particles_->advance(velocity, energy_, dt);
  markBand(velocity, dt, coarseDensity);
  particles_->synthesize(energy_, turbulent_, &nodeMask_);
  applySources(dt);
  updateAdvectingVelocity(velocity);
  advector_.advect(density_, advecting_, dt);
  advector_.advect(temperature_, advecting_, dt);
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
