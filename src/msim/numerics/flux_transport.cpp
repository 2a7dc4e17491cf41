#include "msim/numerics/flux_transport.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// Monotonized-central slope limiter (van Leer 1977): second order where the data are smooth,
// zero slope at extrema, so reconstructed face values never leave the range of the neighbours.
inline float mcSlope(float backward, float forward) {
  if (backward * forward <= 0.0f) return 0.0f;
  const float m = std::min({2.0f * std::abs(backward), 2.0f * std::abs(forward), 0.5f * std::abs(backward + forward)});
  return backward > 0.0f ? m : -m;
}

template <int D>
IVec<D> unit(int axis) {
  IVec<D> e = IVec<D>::Zero();
  e[axis] = 1;
  return e;
}

}  // namespace

template <int D>
FluxTransport<D>::FluxTransport(const GridSpec<D>& spec, const TransportBoundaries<D>& boundaries)
    : spec_(spec),
      boundaries_(boundaries),
      solid_(spec, 0.0f),
      flux_(spec),
      velocity_(spec),
      openVelocity_(spec),
      netOutflow_(spec),
      courantSum_(spec),
      stage_(spec),
      rate_(spec) {}

template <int D>
void FluxTransport<D>::setSolid(const Grid<float, D>& solidMask) {
  solid_ = solidMask;
  updateOpenVelocity();
}

template <int D>
void FluxTransport<D>::setVelocity(const MacGrid<D>& velocity) {
  velocity_ = velocity;
  updateOpenVelocity();
}

template <int D>
void FluxTransport<D>::updateOpenVelocity() {
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    auto& open = openVelocity_.component(a);
    parallelForCells<D>(open.size(), [&](const IVec<D>& f, std::size_t lin) {
      open[lin] = faceOpen(a, f) ? u[lin] : 0.0f;
    });
  }
  // Per fluid cell: the Courant sum (over axes, the larger |u| of its two faces) for the stable
  // step, and the net outflow sum_a (u_upper - u_lower) = dx div(u) for the advective form.
  parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
    float sum = 0.0f, outflow = 0.0f;
    for (int a = 0; a < D; ++a) {
      const auto& u = openVelocity_.component(a);
      IVec<D> upper = c;
      upper[a] += 1;
      sum += std::max(std::abs(u(c)), std::abs(u(upper)));
      outflow += u(upper) - u(c);
    }
    courantSum_[lin] = sum;
    netOutflow_[lin] = outflow;
  });
  maxCourantSum_ = parallelMax(courantSum_.count(), [&](std::size_t i) { return courantSum_[i]; });
}

template <int D>
bool FluxTransport<D>::faceOpen(int axis, const IVec<D>& face) const {
  const bool hasLower = face[axis] > 0;
  const bool hasUpper = face[axis] < spec_.res[axis];
  const IVec<D> e = unit<D>(axis);
  if (hasLower && solid_(face - e) > 0.5f) return false;
  if (hasUpper && solid_(face) > 0.5f) return false;
  if (!hasLower) return boundaries_.side[axis][0] == BoundaryKind::Open;
  if (!hasUpper) return boundaries_.side[axis][1] == BoundaryKind::Open;
  return true;
}

template <int D>
double FluxTransport<D>::maxStableDt(double diffusivity) const {
  // MUSCL with the MC limiter and SSP-RK2 stays positive for Courant sums up to 1/2; explicit
  // diffusion needs 2 D kappa dt / dx^2 <= 1. The two rates add.
  const double rate = maxCourantSum_ / (0.5 * spec_.dx) + 2.0 * D * diffusivity / (spec_.dx * spec_.dx);
  return rate > 0.0 ? 1.0 / rate : std::numeric_limits<double>::infinity();
}

template <int D>
void FluxTransport<D>::evaluateRate(const Grid<float, D>& phi, const TransportSettings& settings,
                                    Grid<float, D>& rate) {
  const float kappaOverDx = static_cast<float>(settings.diffusivity / spec_.dx);
  const float inflow = static_cast<float>(settings.inflowValue);
  const float* p = phi.data().data();
  const float* solid = solid_.data().data();
  for (int a = 0; a < D; ++a) {
    const auto& u = openVelocity_.component(a);
    auto& flux = flux_.component(a);
    const std::ptrdiff_t s = phi.stride(a);  // cell index step along axis a
    const int n = spec_.res[a];
    // Linear indices throughout: this loop is the solver's hot spot.
    parallelForCells<D>(flux.size(), [&](const IVec<D>& f, std::size_t lin) {
      const float uf = u[lin];
      const int i = f[a];
      std::ptrdiff_t cell = 0;  // the cell above the face (index of f in the cell grid)
      for (int b = 0; b < D; ++b) cell += f[b] * phi.stride(b);
      if (i == 0 || i == n) {
        // Domain boundary: closed sides and solid neighbours have uf == 0 and carry nothing;
        // open sides let the upwind interior value out and the inflow value in, with no diffusion.
        if (uf == 0.0f) {
          flux[lin] = 0.0f;
          return;
        }
        const bool outflow = (i == 0) ? uf < 0.0f : uf > 0.0f;
        flux[lin] = uf * (outflow ? p[i == 0 ? cell : cell - s] : inflow);
        return;
      }
      const std::ptrdiff_t left = cell - s;
      const float phiL = p[left], phiR = p[cell];
      const bool fluidPair = solid[left] <= 0.5f && solid[cell] <= 0.5f;
      float total = fluidPair ? -kappaOverDx * (phiR - phiL) : 0.0f;
      if (uf > 0.0f) {
        const bool smooth = i >= 2 && solid[left - s] <= 0.5f;
        const float slope = smooth ? mcSlope(phiL - p[left - s], phiR - phiL) : 0.0f;
        total += uf * (phiL + 0.5f * slope);
      } else if (uf < 0.0f) {
        const bool smooth = i + 1 < n && solid[cell + s] <= 0.5f;
        const float slope = smooth ? mcSlope(phiR - phiL, p[cell + s] - phiR) : 0.0f;
        total += uf * (phiR - 0.5f * slope);
      }
      flux[lin] = total;
    });
  }
  const float invDx = static_cast<float>(1.0 / spec_.dx);
  const bool advective = settings.form == TransportForm::Advective;
  parallelForCells<D>(spec_.res, [&](const IVec<D>& c, std::size_t lin) {
    if (solid_[lin] > 0.5f) {
      rate[lin] = 0.0f;
      return;
    }
    float netOut = 0.0f;
    for (int a = 0; a < D; ++a) {
      const auto& flux = flux_.component(a);
      const std::size_t lower = flux.index(c);
      netOut += flux[lower + flux.stride(a)] - flux[lower];
    }
    float r = -netOut * invDx;
    if (advective) r += phi[lin] * netOutflow_[lin] * invDx;
    rate[lin] = r;
  });
}

template <int D>
void FluxTransport<D>::step(Grid<float, D>& phi, const TransportSettings& settings, double dt) {
  const float h = static_cast<float>(dt);
  // SSP-RK2 (Shu & Osher): phi1 = phi + h L(phi); phi_new = (phi + phi1 + h L(phi1)) / 2.
  evaluateRate(phi, settings, rate_);
  parallelFor(0, phi.count(), [&](std::size_t i) { stage_[i] = phi[i] + h * rate_[i]; });
  evaluateRate(stage_, settings, rate_);
  parallelFor(0, phi.count(), [&](std::size_t i) { phi[i] = 0.5f * (phi[i] + stage_[i] + h * rate_[i]); });
}

template class FluxTransport<2>;
template class FluxTransport<3>;

}  // namespace msim::numerics
