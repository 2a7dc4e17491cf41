#include "msim/turbulence/turbulent_energy.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::turbulence {

template <int D>
TurbulentEnergy<D>::TurbulentEnergy(const GridSpec<D>& spec, const TurbulentEnergyParams& params)
    : spec_(spec),
      params_(params),
      largestEddy_(params.largestEddy > 0.0 ? params.largestEddy : 4.0 * spec.dx),
      energy_(spec, static_cast<float>(params.initialEnergy)),
      strain2_(spec, 0.0f),
      filtered_(spec, 0.0f),
      scratch_(spec, 0.0f),
      solid_(spec, 0.0f),
      advector_(spec, params.advection) {
  if (!(params.viscosity >= 0.0) || !std::isfinite(params.viscosity))
    throw std::invalid_argument("TurbulentEnergy: the viscosity must be >= 0");
  if (!(params.initialEnergy >= 0.0) || !std::isfinite(params.initialEnergy))
    throw std::invalid_argument("TurbulentEnergy: the initial energy must be >= 0");
  if (!(params.eddyViscosityConstant > 0.0) || !std::isfinite(params.eddyViscosityConstant))
    throw std::invalid_argument("TurbulentEnergy: the eddy viscosity constant must be > 0");
}

template <int D>
void TurbulentEnergy<D>::setSolid(const Grid<float, D>& solid) {
  solid_ = solid;
  hasSolid_ = true;
  advector_.setSolid(solid);
  parallelFor(0, energy_.count(), [&](std::size_t i) {
    if (solid_[i] > 0.5f) energy_[i] = 0.0f;
  });
}

template <int D>
bool TurbulentEnergy<D>::solidAt(const IVec<D>& c) const {
  for (int a = 0; a < D; ++a)
    if (c[a] < 0 || c[a] >= spec_.res[a]) return true;  // beyond a wall
  return hasSolid_ && solid_(c) > 0.5f;
}

template <int D>
void TurbulentEnergy<D>::strainRateSquared(const MacGrid<D>& velocity, Grid<float, D>& out) const {
  const double h = spec_.dx;
  // The centre velocity of cell c: the mean of its two faces per axis; zero in walls and solids.
  auto centre = [&](const IVec<D>& c, int i) {
    if (solidAt(c)) return 0.0;
    IVec<D> upper = c;
    upper[i] += 1;
    const auto& u = velocity.component(i);
    return 0.5 * (double(u(c)) + double(u(upper)));
  };
  parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
    if (solidAt(c)) {
      out[lin] = 0.0f;
      return;
    }
    double grad[D][D];  // grad[i][j] = dU_i / dx_j
    for (int i = 0; i < D; ++i) {
      IVec<D> upper = c;
      upper[i] += 1;
      grad[i][i] = (double(velocity.component(i)(upper)) - double(velocity.component(i)(c))) / h;
      for (int j = 0; j < D; ++j) {
        if (j == i) continue;
        IVec<D> plus = c, minus = c;
        plus[j] += 1;
        minus[j] -= 1;
        grad[i][j] = (centre(plus, i) - centre(minus, i)) / (2.0 * h);
      }
    }
    double s2 = 0.0;
    for (int i = 0; i < D; ++i)
      for (int j = 0; j < D; ++j) {
        const double sij = 0.5 * (grad[i][j] + grad[j][i]);
        s2 += sij * sij;
      }
    out[lin] = static_cast<float>(s2);
  });
}

template <int D>
double TurbulentEnergy<D>::react(double energy, double cStrain2, double k0, double dt) {
  const double a = cStrain2 / k0, b = k0;
  const double e = std::max(energy, 0.0);
  if (e == 0.0) return 0.0;  // G carries a factor sqrt(E_0): nothing to produce from
  const double root = std::sqrt(e);
  const double equilibrium = a / b;  // f(E) = 0: C S^2 l_0^2
  const double slope = a / (2.0 * root) - 1.5 * b * root;
  if (slope > 0.0) {
    // Growing towards the equilibrium from below: forward Euler, not past it.
    const double next = e + dt * (a * root - b * e * root);
    return std::min(next, std::max(equilibrium, e));
  }
  // Backward Euler: s = sqrt(E^{n+1}) solves b dt s^3 + s^2 - a dt s - E^n = 0, which has exactly
  // one positive root (one sign change). Newton from above the root: the cubic is convex there.
  double s = std::max(root, std::sqrt(equilibrium));
  for (int it = 0; it < 60; ++it) {
    const double f = b * dt * s * s * s + s * s - a * dt * s - e;
    const double df = 3.0 * b * dt * s * s + 2.0 * s - a * dt;
    const double next = s - f / df;
    if (!(next > 0.0)) {
      s *= 0.5;
      continue;
    }
    if (std::abs(next - s) <= 1e-14 * s) {
      s = next;
      break;
    }
    s = next;
  }
  return s * s;
}

template <int D>
void TurbulentEnergy<D>::filteredEnergy(Grid<float, D>& out) const {
  // Separable Gaussian of standard deviation l_0 / 2 (truncated at 3 sigma), weights renormalised
  // over the fluid cells each line holds, so walls and solids do not pull the filter down.
  const double sigma = 0.5 * largestEddy_ / spec_.dx;
  const int radius = std::max(1, static_cast<int>(std::ceil(3.0 * sigma)));
  std::vector<double> w(static_cast<std::size_t>(radius) + 1);
  for (int k = 0; k <= radius; ++k) w[k] = std::exp(-0.5 * k * k / (sigma * sigma));
  out = energy_;
  Grid<float, D> tmp(spec_, 0.0f);
  for (int a = 0; a < D; ++a) {
    tmp = out;
    parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
      if (solidAt(c)) {
        out[lin] = 0.0f;
        return;
      }
      double sum = 0.0, weight = 0.0;
      for (int k = -radius; k <= radius; ++k) {
        IVec<D> n = c;
        n[a] += k;
        if (solidAt(n)) continue;
        sum += w[std::abs(k)] * tmp(n);
        weight += w[std::abs(k)];
      }
      out[lin] = static_cast<float>(sum / weight);
    });
  }
}

template <int D>
void TurbulentEnergy<D>::diffuse(double dt) {
  // Eq. 3.11: dE/dt = div(kappa grad E), kappa = C k_0^-1 sqrt(E~) frozen over the step, implicit
  // along one axis after the other (tridiagonal solves per line); no flux through walls and solids.
  filteredEnergy(filtered_);
  parallelFor(0, filtered_.count(), [&](std::size_t i) {
    filtered_[i] = static_cast<float>(params_.eddyViscosityConstant * largestEddy_ * std::sqrt(std::max(filtered_[i], 0.0f)));
  });
  const double r = dt / (spec_.dx * spec_.dx);
  for (int a = 0; a < D; ++a) {
    const int n = spec_.res[a];
    // The lines along axis a: every cell with coordinate 0 along a.
    IVec<D> lineCount = spec_.res;
    lineCount[a] = 1;
    const std::size_t lines = static_cast<std::size_t>(lineCount.prod());
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, lines, 16), [&](const tbb::blocked_range<std::size_t>& range) {
      std::vector<double> lower(n), diag(n), upper(n), rhs(n);  // once per task, not per line
      for (std::size_t line = range.begin(); line != range.end(); ++line) {
        IVec<D> start;
        std::size_t rest = line;
        for (int d = 0; d < D; ++d) {
          start[d] = static_cast<int>(rest % lineCount[d]);
          rest /= lineCount[d];
        }
        IVec<D> c = start;
        auto kappaFace = [&](int k) {  // between cells k - 1 and k along the line
          IVec<D> lo = start, hi = start;
          lo[a] = k - 1;
          hi[a] = k;
          if (solidAt(lo) || solidAt(hi)) return 0.0;
          return 0.5 * (double(filtered_(lo)) + double(filtered_(hi)));
        };
        for (int k = 0; k < n; ++k) {
          c[a] = k;
          const double left = r * kappaFace(k), right = r * kappaFace(k + 1);
          lower[k] = -left;
          upper[k] = -right;
          diag[k] = 1.0 + left + right;
          rhs[k] = energy_(c);
        }
        // Thomas algorithm.
        for (int k = 1; k < n; ++k) {
          const double m = lower[k] / diag[k - 1];
          diag[k] -= m * upper[k - 1];
          rhs[k] -= m * rhs[k - 1];
        }
        rhs[n - 1] /= diag[n - 1];
        for (int k = n - 2; k >= 0; --k) rhs[k] = (rhs[k] - upper[k] * rhs[k + 1]) / diag[k];
        for (int k = 0; k < n; ++k) {
          c[a] = k;
          energy_(c) = static_cast<float>(rhs[k]);
        }
      }
    });
  }
}

template <int D>
void TurbulentEnergy<D>::step(const MacGrid<D>& velocity, double dt) {
  if (params_.diffusion) diffuse(dt);
  advector_.advect(energy_, velocity, dt);
  strainRateSquared(velocity, strain2_);
  const double k = k0(), constant = params_.eddyViscosityConstant;
  parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
    if (solidAt(c)) {
      energy_[lin] = 0.0f;
      return;
    }
    energy_[lin] = static_cast<float>(react(energy_[lin], constant * strain2_[lin], k, dt));
  });
}

template <int D>
double TurbulentEnergy<D>::viscousCutoff(double energy) const {
  if (params_.viscosity == 0.0) return std::numeric_limits<double>::infinity();
  const double cascade = k0() * std::pow(std::max(energy, 0.0), 1.5);
  return std::pow(cascade / (params_.viscosity * params_.viscosity * params_.viscosity), 0.25);
}

template <int D>
double TurbulentEnergy<D>::octaveEnergy(double energy, int octave) const {
  const double k = k0() * std::ldexp(1.0, octave), cutoff = viscousCutoff(energy);
  const double e = energy * std::pow(k / k0(), -2.0 / 3.0);
  if (2.0 * k < cutoff) return e;
  if (cutoff < k) return 0.0;
  return e * (cutoff - k) / k;
}

template <int D>
double TurbulentEnergy<D>::integral() const {
  return spec_.cellVolume() * parallelSum(energy_.count(), [&](std::size_t i) { return double(energy_[i]); });
}

template class TurbulentEnergy<2>;
template class TurbulentEnergy<3>;

}  // namespace msim::turbulence
