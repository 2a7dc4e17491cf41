#include "msim/numerics/advection/advector.hpp"

#include <algorithm>
#include <cmath>
#include <cstring>
#include <utility>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"
#include "msim/numerics/advection/building_blocks.hpp"

namespace msim::numerics {

namespace {

// f(begin, end) over blocks of [0, n), in parallel: lets the loop body be a plain vectorisable loop.
template <typename F>
void parallelForBlocks(std::size_t n, F&& f) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, n, 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) { f(r.begin(), r.end()); });
}

}  // namespace

template <typename T, int D>
Advector<T, D>::Advector(const GridSpec<D>& spec, const AdvectionSettings& settings,
                         const AxisBoundaries<D>& boundaries, const BlockPlacement<D>& placement)
    : spec_(spec), settings_(settings), boundaries_(boundaries), placement_(placement) {}

template <typename T, int D>
void Advector<T, D>::setSolid(const Grid<float, D>& mask) {
  solid_ = mask;
  ++solidVersion_;
}

template <typename T, int D>
typename Advector<T, D>::Scratch& Advector<T, D>::scratchFor(const Grid<T, D>& field, int slot) {
  Scratch& s = scratch_[slot];
  if (!s.forward.sameLayout(field)) {
    const Grid<T, D> blank(field.spec(), field.size(), field.offset());
    s.forward = s.backward = s.corrected = s.lo = s.hi = blank;
    s.solid.assign(field.count(), 0);
    s.touched.assign(field.count(), 0);
    s.solidVersion = 0;
  }
  return s;
}

// A sample is solid when it lies in or on the boundary of a solid cell: a cell centre in its
// cell, a MAC face when either cell it separates is solid.
template <typename T, int D>
const std::uint8_t* Advector<T, D>::solidSamples(const Grid<T, D>& field, Scratch& s) {
  if (!solid_) return nullptr;
  if (s.solidVersion == solidVersion_) return s.solid.data();
  s.solidVersion = solidVersion_;
  std::vector<std::uint8_t>& flags = s.solid;
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
  return flags.data();
}

// Copies `velocity` into velocity_ unless it holds the same values already (then the cached feet
// stay valid). Comparing costs one read of both fields, far less than tracing a single layout.
template <typename T, int D>
void Advector<T, D>::holdVelocity(const MacGrid<D>& velocity) {
  bool same = velocity_.spec() == velocity.spec();
  for (int a = 0; a < D && same; ++a) {
    const auto& held = velocity_.component(a).data();
    const auto& given = velocity.component(a).data();
    same = held.size() == given.size() && std::memcmp(held.data(), given.data(), held.size() * sizeof(float)) == 0;
  }
  if (!same) {
    velocity_ = velocity;
    feet_.valid = false;
  }
}

template <typename T, int D>
const typename Advector<T, D>::FeetCache& Advector<T, D>::feetFor(const Grid<T, D>& field, double dt,
                                                                  const std::uint8_t* solid) {
  FeetCache& f = feet_;
  const std::uint64_t solidVersion = solid ? solidVersion_ : 0;
  if (f.valid && f.spec == field.spec() && f.size == field.size() && f.offset == field.offset() && f.dt == dt &&
      f.trace == settings_.trace && f.solidVersion == solidVersion)
    return f;
  f.spec = field.spec();
  f.size = field.size();
  f.offset = field.offset();
  f.dt = dt;
  f.trace = settings_.trace;
  f.solidVersion = solidVersion;
  f.touched.assign(solid ? field.count() : 0, 0);
  traceFeet<T, D>(field, boundaries_, velocity_, dt, settings_.trace, solid, f.forward, f.backward,
                  solid ? f.touched.data() : nullptr, placement_);
  f.valid = true;
  return f;
}

template <typename T, int D>
void Advector<T, D>::advect(Grid<T, D>& field, const MacGrid<D>& velocity, double dt) {
  holdVelocity(velocity);
  advectComponent(field, dt, scratchFor(field, 0));
}

template <typename T, int D>
void Advector<T, D>::advect(MacGrid<D>& field, const MacGrid<D>& velocity, double dt)
  requires std::same_as<T, float>
{
  // Every component moves with the held copy, so self-advection sees the velocity of time n.
  holdVelocity(velocity);
  for (int a = 0; a < D; ++a) advectComponent(field.component(a), dt, scratchFor(field.component(a), 1 + a));
}

template <typename T, int D>
void Advector<T, D>::advectComponent(Grid<T, D>& field, double dt, Scratch& s) {
  const AdvectionSettings& cfg = settings_;
  const FieldLayout<D> layout = FieldLayout<D>::of(field, boundaries_, placement_);
  const std::uint8_t* solid = solidSamples(field, s);
  const bool nearSolidRule = solid && cfg.firstOrderNearSolids;
  const bool semiLagrangian = cfg.block == BuildingBlock::SemiLagrangian;
  const FeetCache* feet = semiLagrangian ? &feetFor(field, dt, solid) : nullptr;
  const SampleLattice<D> lattice(layout);
  // One building-block step forwards (V) or backwards (-V); the semi-Lagrangian feet already know
  // which samples are solid and which stencils touch solids.
  auto step = [&](const Grid<T, D>& src, Grid<T, D>& dst, bool backward, const StepOutputs<T>& out) {
    if (semiLagrangian)
      sampleAtFeet<T, D>(lattice, backward ? feet->backward : feet->forward, src.data().data(), dst.data().data(),
                         out.lo, out.hi);
    else
      upwindStep(layout, src, dst, VelocitySampler<D>(velocity_, boundaries_, backward ? -1.0 : 1.0), dt, solid, out);
  };
  const bool upwindTouched = nearSolidRule && !semiLagrangian;
  if (upwindTouched) std::fill(s.touched.begin(), s.touched.end(), std::uint8_t{0});

  // phi_hat^{n+1} = A(phi^n), remembering the range of the samples each value was built from.
  step(field, s.forward, false, {s.lo.data().data(), s.hi.data().data(), upwindTouched ? s.touched.data() : nullptr});
  if (cfg.scheme == AdvectionScheme::FirstOrder) {
    std::swap(field.data(), s.forward.data());
    return;
  }
  // phi_hat^n = A^R(phi_hat^{n+1}); e = (phi_hat^n - phi^n)/2 (ch. 2.4).
  step(s.forward, s.backward, true, {nullptr, nullptr, upwindTouched ? s.touched.data() : nullptr});

  const T* phi = field.data().data();
  const T* hatNext = s.forward.data().data();
  const T* hatNow = s.backward.data().data();
  const bool bfecc = cfg.scheme == AdvectionScheme::BFECC;
  if (bfecc) {
    // phi_bar^n = phi^n - e, then phi^{n+1} = A(phi_bar^n) into `backward` (its phi_hat^n is used up).
    T* bar = s.corrected.data().data();
    parallelFor(0, field.count(), [&](std::size_t i) { bar[i] = static_cast<T>(phi[i] - 0.5 * (hatNow[i] - phi[i])); });
    step(s.corrected, s.backward, false, {});
  }

  const T* lo = s.lo.data().data();
  const T* hi = s.hi.data().data();
  const std::uint8_t* touched = !nearSolidRule ? nullptr : (semiLagrangian ? feet->touched.data() : s.touched.data());
  T* out = field.data().data();
  // The limiter is a template argument so each variant is one branch-free, vectorised loop.
  auto finish = [&]<ExtremaLimiter L>() {
    parallelForBlocks(field.count(), [&](std::size_t begin, std::size_t end) {
      for (std::size_t i = begin; i < end; ++i) {
        // BFECC: the third step's result; MacCormack: phi^{n+1} = phi_hat^{n+1} - e (ch. 2.4).
        const T v = bfecc ? hatNow[i] : static_cast<T>(hatNext[i] - 0.5 * (hatNow[i] - out[i]));
        T r = v;
        if constexpr (L == ExtremaLimiter::ClampExtrema) r = std::clamp(v, lo[i], hi[i]);
        if constexpr (L == ExtremaLimiter::RevertToFirstOrder) r = (v < lo[i] || v > hi[i]) ? hatNext[i] : v;
        if (touched) r = touched[i] ? hatNext[i] : r;  // ch. 2.9: the error estimate mixed fluid and solid data
        if (solid) r = solid[i] ? out[i] : r;          // values inside solids stay as they are
        out[i] = r;
      }
    });
  };
  switch (cfg.limiter) {
    case ExtremaLimiter::None: finish.template operator()<ExtremaLimiter::None>(); break;
    case ExtremaLimiter::ClampExtrema: finish.template operator()<ExtremaLimiter::ClampExtrema>(); break;
    case ExtremaLimiter::RevertToFirstOrder: finish.template operator()<ExtremaLimiter::RevertToFirstOrder>(); break;
  }
}

template class Advector<float, 2>;
template class Advector<float, 3>;
template class Advector<double, 2>;
template class Advector<double, 3>;

}  // namespace msim::numerics
