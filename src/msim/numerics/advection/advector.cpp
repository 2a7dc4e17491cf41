#include "msim/numerics/advection/advector.hpp"

#include <algorithm>
#include <cmath>
#include <utility>

#include "msim/core/parallel.hpp"
#include "msim/numerics/advection/building_blocks.hpp"

namespace msim::numerics {

template <typename T, int D>
Advector<T, D>::Advector(const GridSpec<D>& spec, const AdvectionSettings& settings,
                         const AxisBoundaries<D>& boundaries)
    : spec_(spec), settings_(settings), boundaries_(boundaries) {}

template <typename T, int D>
void Advector<T, D>::setSolid(const Grid<float, D>& mask) {
  solid_ = mask;
}

template <typename T, int D>
typename Advector<T, D>::Scratch& Advector<T, D>::scratchFor(const Grid<T, D>& field, int slot) {
  Scratch& s = scratch_[slot];
  if (!s.forward.sameLayout(field)) {
    const Grid<T, D> blank(field.spec(), field.size(), field.offset());
    s.forward = s.backward = s.corrected = s.lo = s.hi = blank;
    s.solid.assign(field.count(), 0);
    s.touched.assign(field.count(), 0);
  }
  return s;
}

// A sample is solid when it lies in or on the boundary of a solid cell: a cell centre in its
// cell, a MAC face when either cell it separates is solid.
template <typename T, int D>
void Advector<T, D>::markSolidSamples(const Grid<T, D>& field, std::vector<std::uint8_t>& flags) const {
  const Grid<float, D>& mask = *solid_;
  parallelForCells<D>(field.size(), [&](const IVec<D>& c, std::size_t lin) {
    const Vec<D> s = (field.position(c) - spec_.origin) / spec_.dx;  // in cell units
    int first[D], last[D];
    for (int a = 0; a < D; ++a) {
      const double r = std::round(s[a]);
      const bool onFace = std::abs(s[a] - r) < 1e-6;
      first[a] = onFace ? static_cast<int>(r) - 1 : static_cast<int>(std::floor(s[a]));
      last[a] = onFace ? static_cast<int>(r) : first[a];
    }
    bool solid = false;
    for (int k = 0; k < (1 << D) && !solid; ++k) {
      IVec<D> cell;
      for (int a = 0; a < D; ++a) {
        int i = (k >> a) & 1 ? last[a] : first[a];
        const int n = spec_.res[a];
        i = boundaries_[a] == AxisBoundary::Periodic ? ((i % n) + n) % n : std::clamp(i, 0, n - 1);
        cell[a] = i;
      }
      solid = mask(cell) > 0.5f;
    }
    flags[lin] = static_cast<std::uint8_t>(solid);
  });
}

template <typename T, int D>
void Advector<T, D>::advect(Grid<T, D>& field, const MacGrid<D>& velocity, double dt) {
  const VelocitySampler<D> forward(velocity, boundaries_, 1.0), backward(velocity, boundaries_, -1.0);
  advectComponent(field, forward, backward, dt, scratchFor(field, 0));
}

template <typename T, int D>
void Advector<T, D>::advect(MacGrid<D>& field, const MacGrid<D>& velocity, double dt)
  requires std::same_as<T, float>
{
  const MacGrid<D>* carrier = &velocity;
  if (&field == &velocity) {  // self-advection: every component must see the velocity of time n
    if (velocityCopy_.spec() != velocity.spec()) velocityCopy_ = MacGrid<D>(velocity.spec());
    for (int a = 0; a < D; ++a) velocityCopy_.component(a).data() = velocity.component(a).data();
    carrier = &velocityCopy_;
  }
  const VelocitySampler<D> forward(*carrier, boundaries_, 1.0), backward(*carrier, boundaries_, -1.0);
  for (int a = 0; a < D; ++a)
    advectComponent(field.component(a), forward, backward, dt, scratchFor(field.component(a), 1 + a));
}

template <typename T, int D>
void Advector<T, D>::advectComponent(Grid<T, D>& field, const VelocitySampler<D>& forward,
                                     const VelocitySampler<D>& backward, double dt, Scratch& s) {
  const AdvectionSettings& cfg = settings_;
  const FieldLayout<D> layout = FieldLayout<D>::of(field, boundaries_);
  const std::uint8_t* solid = nullptr;
  if (solid_) {
    markSolidSamples(field, s.solid);
    solid = s.solid.data();
  }
  const bool nearSolidRule = solid && cfg.firstOrderNearSolids;
  if (nearSolidRule) std::fill(s.touched.begin(), s.touched.end(), std::uint8_t{0});

  // phi_hat^{n+1} = A(phi^n), remembering the range of the samples each value was built from.
  StepOutputs<T> first{s.lo.data().data(), s.hi.data().data(), nearSolidRule ? s.touched.data() : nullptr};
  firstOrderStep(cfg.block, cfg.trace, layout, field, s.forward, forward, dt, solid, first);
  if (cfg.scheme == AdvectionScheme::FirstOrder) {
    std::swap(field.data(), s.forward.data());
    return;
  }
  // phi_hat^n = A^R(phi_hat^{n+1}); e = (phi_hat^n - phi^n)/2 (ch. 2.4).
  StepOutputs<T> second{nullptr, nullptr, nearSolidRule ? s.touched.data() : nullptr};
  firstOrderStep(cfg.block, cfg.trace, layout, s.forward, s.backward, backward, dt, solid, second);

  const T* phi = field.data().data();
  const T* hatNext = s.forward.data().data();
  const T* hatNow = s.backward.data().data();
  const T* high = nullptr;  // the error-corrected phi^{n+1}
  if (cfg.scheme == AdvectionScheme::BFECC) {
    // phi_bar^n = phi^n - e, then phi^{n+1} = A(phi_bar^n); the third step reuses `backward`.
    T* bar = s.corrected.data().data();
    parallelFor(0, field.count(), [&](std::size_t i) { bar[i] = static_cast<T>(phi[i] - 0.5 * (hatNow[i] - phi[i])); });
    firstOrderStep(cfg.block, cfg.trace, layout, s.corrected, s.backward, forward, dt, solid, StepOutputs<T>{});
    high = s.backward.data().data();
  } else {
    // MacCormack: phi^{n+1} = phi_hat^{n+1} - e (ch. 2.4); written into `corrected`.
    T* mac = s.corrected.data().data();
    parallelFor(0, field.count(), [&](std::size_t i) { mac[i] = static_cast<T>(hatNext[i] - 0.5 * (hatNow[i] - phi[i])); });
    high = mac;
  }

  const T* lo = s.lo.data().data();
  const T* hi = s.hi.data().data();
  const std::uint8_t* touched = s.touched.data();
  T* out = field.data().data();
  parallelFor(0, field.count(), [&](std::size_t i) {
    if (solid && solid[i]) return;  // values inside solids stay as they are
    if (nearSolidRule && touched[i]) {
      out[i] = hatNext[i];  // ch. 2.9: the error estimate mixed fluid and solid data
      return;
    }
    const T v = high[i];
    switch (cfg.limiter) {
      case ExtremaLimiter::None: out[i] = v; break;
      case ExtremaLimiter::ClampExtrema: out[i] = std::clamp(v, lo[i], hi[i]); break;
      case ExtremaLimiter::RevertToFirstOrder: out[i] = (v < lo[i] || v > hi[i]) ? hatNext[i] : v; break;
    }
  });
}

template class Advector<float, 2>;
template class Advector<float, 3>;
template class Advector<double, 2>;
template class Advector<double, 3>;

}  // namespace msim::numerics
