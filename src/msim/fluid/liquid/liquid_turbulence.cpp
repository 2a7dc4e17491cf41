#include "msim/fluid/liquid/liquid_turbulence.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <optional>
#include <stdexcept>
#include <utility>

#include "msim/core/parallel.hpp"
#include "msim/core/resample.hpp"

namespace msim::fluid {

namespace {

// tau' = dx / c, c = sqrt(g dx / (2 pi)): the period-scale of deep-water waves one cell long (eq. 3.13).
double rippleTimescale(double dx, double gravity) {
  if (!(gravity > 0.0)) throw std::invalid_argument("LiquidTurbulence: gravity must be > 0 (it sets the ripples' time scale)");
  return dx / std::sqrt(gravity * dx / (2.0 * std::numbers::pi));
}

}  // namespace

template <int D>
LiquidTurbulence<D>::LiquidTurbulence(const GridSpec<D>& coarse, const LiquidTurbulenceParams& params,
                                      const numerics::AdvectionSettings& advection, const Grid<float, D>& coarsePhi,
                                      const Grid<float, D>* coarseSolid)
    : params_(params),
      tau_(rippleTimescale(coarse.dx, params.gravity)),
      model_(coarse, params, advection, coarseSolid),
      coarse_(coarse),
      fine_(model_.fineSpec()),
      phi_(fine_),
      smoothed_(fine_),
      detail_(fine_, 0.0f),
      ripple_(coarse, 0.0f) {
  resetSurface(coarsePhi);
}

template <int D>
void LiquidTurbulence<D>::resetSurface(const Grid<float, D>& coarsePhi) {
  resampleLinear<D>(coarsePhi, smoothed_);
  phi_ = smoothed_;
  detail_.fill(0.0f);
  ripple_.fill(0.0f);
  meanDelta_ = 0.0;
}

template <int D>
void LiquidTurbulence<D>::restoreSurface(const Grid<float, D>& finePhi, const Grid<float, D>& coarsePhi) {
  if (!finePhi.sameLayout(phi_)) throw std::invalid_argument("LiquidTurbulence: the fine surface has another layout");
  resetSurface(coarsePhi);
  phi_ = finePhi;
  parallelFor(0, detail_.count(), [&](std::size_t i) { detail_[i] = phi_[i] - smoothed_[i]; }, 1 << 14);
}

template <int D>
void LiquidTurbulence<D>::step(const MacGrid<D>& velocity, const Grid<float, D>& coarsePhi, double dt) {
  // 1. Energy, none in the air away from the surface.
  std::optional<ScopedStage> stage(std::in_place, timers_, "energy");
  model_.stepEnergy(velocity, dt);
  const float airPhi = static_cast<float>(kAirCells * coarse_.dx);
  Grid<float, D>& e = model_.energy().energy();
  parallelFor(0, e.count(), [&](std::size_t i) {
    if (coarsePhi[i] > airPhi) e[i] = 0.0f;
  }, 4096);
  // 2-4. Particles, the band round the surface, u'.
  stage.emplace(timers_, "noise");
  const Grid<float, D>& solid = model_.coarseSolid();
  const float surfacePhi = static_cast<float>(kSurfaceCells * coarse_.dx);
  seeds_.resize(coarsePhi.count());
  parallelFor(0, seeds_.size(), [&](std::size_t i) {
    seeds_[i] = std::abs(coarsePhi[i]) < surfacePhi && solid[i] <= 0.5f;
  }, 4096);
  model_.synthesize(velocity, dt, seeds_, &ripple_);
  // 5-6. The detail as U + u' carries phi and U alone carries phi~, then eq. 3.13.
  stage.emplace(timers_, "surface advection");
  boxLo_ = model_.boxLo();
  boxHi_ = model_.boxHi();
  model_.advect({&detail_}, velocity, dt);
  if (boxHi_ != boxLo_) subtractEddyTransport(dt);
  stage.emplace(timers_, "surface relaxation");
  relax(coarsePhi, dt);
  // 7. The ripples' height and energy.
  measureRipples(coarsePhi);
}

template <int D>
void LiquidTurbulence<D>::relax(const Grid<float, D>& coarsePhi, double dt) {
  // phi = phi~(new) + (1 - k) eta, k = dt / tau' (eq. 3.13 by forward Euler, at most the whole way
  // in one step): what the tracker did to its surface beyond carrying it (particle corrections,
  // emitters, sinks, volume control) shows at once, and the detail decays over tau'. Outside the
  // advected box the surface is far (beyond the band's reach) and there is no detail. The detail
  // is held within one simulation cell: larger features are the simulation's to resolve.
  const float k = static_cast<float>(std::min(1.0, dt / tau_));
  const float largest = static_cast<float>(coarse_.dx);
  // Row by row along x (fine cells): the box's part of each row, [x0, x1), or none.
  const int nx = fine_.res[0];
  std::size_t rows = 1;
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(fine_.res[d]);
  auto boxSpan = [&](std::size_t row) {
    std::size_t rest = row;
    bool inside = boxHi_ != boxLo_;
    for (int d = 1; d < D; ++d) {
      const int c = static_cast<int>(rest % static_cast<std::size_t>(fine_.res[d]));
      rest /= static_cast<std::size_t>(fine_.res[d]);
      inside = inside && c >= boxLo_[d] && c < boxHi_[d];
    }
    return inside ? std::pair<int, int>(boxLo_[0], boxHi_[0]) : std::pair<int, int>(0, 0);
  };
  resampleLinear<D>(coarsePhi, smoothed_);
  parallelFor(0, rows, [&](std::size_t row) {
    const auto [x0, x1] = boxSpan(row);
    const std::size_t start = row * static_cast<std::size_t>(nx);
    float* eta = detail_.data().data() + start;
    float* phi = phi_.data().data() + start;
    const float* smoothed = smoothed_.data().data() + start;
    for (int x = 0; x < nx; ++x) {
      eta[x] = x >= x0 && x < x1 ? (1.0f - k) * std::clamp(eta[x], -largest, largest) : 0.0f;
      phi[x] = smoothed[x] + eta[x];
    }
  }, 16);
}

template <int D>
void LiquidTurbulence<D>::subtractEddyTransport(double dt) {
  // U + u' carries phi~ to phi~(x - (U + u') dt) = phi~(x - U dt) - dt u' . grad phi~ to first
  // order, so the detail that U + u' makes on top of what U alone does is A_(U+u')(eta) -
  // dt u' . grad phi~ (A the advection, linear in what it carries). One advection instead of
  // carrying phi by U + u' and phi~ by U: half the surface's cost. grad phi~ by central
  // differences (one-sided at the grid's ends), u' at the cell centres from its two faces.
  const IVec<D> size = boxHi_ - boxLo_;
  parallelForCells<D>(size, [&](const IVec<D>& local, std::size_t) {
    const IVec<D> c = boxLo_ + local;
    double transport = 0.0;
    for (int a = 0; a < D; ++a) {
      IVec<D> lo = c, hi = c;
      lo[a] = std::max(c[a] - 1, 0);
      hi[a] = std::min(c[a] + 1, fine_.res[a] - 1);
      const double gradient = (smoothed_(hi) - smoothed_(lo)) / ((hi[a] - lo[a]) * fine_.dx);
      IVec<D> up = c;
      up[a] += 1;
      const auto& u = model_.turbulentVelocity().component(a);
      transport += 0.5 * (u(c) + u(up)) * gradient;
    }
    detail_(c) -= static_cast<float>(dt * transport);
  });
}

template <int D>
void LiquidTurbulence<D>::measureRipples(const Grid<float, D>& coarsePhi) {
  // delta: the mean |phi - phi~| over the fine cells within one simulation cell of the surface
  // (the fine surface's displacement where |grad phi| ~ 1), per simulation cell near the surface;
  // E' = (delta / tau')^2 (eq. 3.14).
  const int r = params_.refinement;
  const float near = static_cast<float>(coarse_.dx);
  const float surfacePhi = static_cast<float>(kSurfaceCells * coarse_.dx);
  IVec<D> block = IVec<D>::Constant(r);
  int blockCells = 1;
  for (int d = 0; d < D; ++d) blockCells *= r;
  std::vector<double>& delta = delta_;
  delta.assign(ripple_.count(), -1.0);
  parallelForCells<D>(coarse_.res, [&](const IVec<D>& c, std::size_t lin) {
    ripple_[lin] = 0.0f;
    if (!(std::abs(coarsePhi[lin]) < surfacePhi) || model_.coarseSolid()[lin] > 0.5f) return;
    double sum = 0.0;
    int count = 0;
    for (int k = 0; k < blockCells; ++k) {
      IVec<D> f = c * r;
      int rest = k;
      for (int d = 0; d < D; ++d) {
        f[d] += rest % block[d];
        rest /= block[d];
      }
      const std::size_t fi = phi_.index(f);
      if (std::abs(smoothed_[fi]) >= near) continue;
      sum += std::abs(detail_[fi]);
      ++count;
    }
    if (count == 0) return;
    delta[lin] = sum / count;
    const double rate = delta[lin] / tau_;
    ripple_[lin] = static_cast<float>(rate * rate);
  });
  double sum = 0.0;
  std::size_t cells = 0;
  for (const double d : delta)
    if (d >= 0.0) {
      sum += d;
      ++cells;
    }
  meanDelta_ = cells > 0 ? sum / static_cast<double>(cells) : 0.0;
}

template class LiquidTurbulence<2>;
template class LiquidTurbulence<3>;

}  // namespace msim::fluid
