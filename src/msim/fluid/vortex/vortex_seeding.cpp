#include "msim/fluid/vortex/vortex_seeding.hpp"

#include <array>
#include <cmath>
#include <sstream>
#include <stdexcept>

#include "msim/core/linear_taps.hpp"

namespace msim::fluid {

namespace {

[[noreturn]] void fail(const std::string& context, const std::string& field, const std::string& what) {
  throw std::invalid_argument(context + "." + field + ": " + what);
}

template <int D>
std::string format(const Vec<D>& v) {
  std::ostringstream s;
  s << "(";
  for (int a = 0; a < D; ++a) s << (a ? ", " : "") << v[a];
  s << ")";
  return s.str();
}

template <int D>
VortexVector<D> randomDirection(Rng& rng) {
  if constexpr (D == 2) {
    return VortexVector<D>(rng.uniform() < 0.5 ? -1.0 : 1.0);
  } else {
    for (;;) {  // three normals give a direction uniform on the sphere
      const Eigen::Vector3d g(rng.normal(), rng.normal(), rng.normal());
      const double n = g.norm();
      if (n > 1e-12) return g / n;
    }
  }
}

// e_up x (x - centre), normalised (2D: the sign of its z component); zero on the axis.
template <int D>
VortexVector<D> azimuthalDirection(const Vec<D>& x, const Vec<D>& centre, int upAxis) {
  const Vec<D> r = x - centre;
  Vec<D> up = Vec<D>::Zero();
  up[upAxis] = 1.0;
  if constexpr (D == 2) {
    const double z = up[0] * r[1] - up[1] * r[0];
    return VortexVector<D>(z > 0.0 ? 1.0 : (z < 0.0 ? -1.0 : 0.0));
  } else {
    const Eigen::Vector3d t = up.cross(r);
    const double n = t.norm();
    return n > 0.0 ? Eigen::Vector3d(t / n) : Eigen::Vector3d::Zero();
  }
}

// Adds `count` particles; LocalFlow reads the flow through `flow` (null: not needed).
template <int D>
std::size_t seed(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings, const GridSpec<D>& domain,
                 std::size_t count, Rng& rng, const FlowVorticitySampler<D>* flow);

}  // namespace

template <int D>
VortexVector<D> flowVorticityAt(const Vorticity<D>& grid, const Vec<D>& x) {
  const Vec<D> s = grid.toSampleSpace(x);
  std::array<LinearTap, D> taps;
  for (int a = 0; a < D; ++a) taps[a] = clampedTap(s[a], grid.size()[a], static_cast<std::size_t>(grid.stride(a)));
  return blendCorners<D>(taps, grid.data().data()).template cast<double>();
}

template <int D>
void VortexSeedSettings<D>::validate(const GridSpec<D>& domain, const std::string& context) const {
  // A box drawn to the domain's written bounds may exceed the grid's origin + res dx by rounding.
  const double slack = 1e-9 * domain.dx;
  const Vec<D> lo = domain.origin.array() - slack, hi = domain.upper().array() + slack;
  for (int a = 0; a < D; ++a) {
    if (!std::isfinite(regionMin[a]) || !std::isfinite(regionMax[a]))
      fail(context, "region", "the corners must be finite, got min " + format<D>(regionMin) + " max " + format<D>(regionMax));
    if (regionMin[a] > regionMax[a])
      fail(context, "region", "min " + format<D>(regionMin) + " exceeds max " + format<D>(regionMax) + " on axis " + std::to_string(a));
    if (regionMin[a] < lo[a] || regionMax[a] > hi[a])
      fail(context, "region",
           "the box " + format<D>(regionMin) + " - " + format<D>(regionMax) + " is not inside the domain " +
               format<D>(lo) + " - " + format<D>(hi));
  }
  requireValidVortexRadius(radius, (context + ".radius").c_str());
  requireValidVortexStrength(strength, (context + ".strength").c_str());
  if (!(std::isfinite(magnitude) && magnitude >= 0.0))
    fail(context, "magnitude", "|omega_p| must be finite and >= 0 1/s, got " + std::to_string(magnitude));
  if (upAxis < 0 || upAxis >= D) fail(context, "up_axis", "must be an axis 0.." + std::to_string(D - 1) + ", got " + std::to_string(upAxis));
  if (!(std::isfinite(minimumFlowVorticity) && minimumFlowVorticity >= 0.0))
    fail(context, "minimum_flow_vorticity", "must be finite and >= 0 1/s, got " + std::to_string(minimumFlowVorticity));
}

template <int D>
std::size_t seedVortexParticles(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings,
                                const GridSpec<D>& domain, std::size_t count, Rng& rng,
                                const Vorticity<D>* flowVorticity) {
  if (settings.vorticity != SeedVorticity::LocalFlow) return seed<D>(particles, settings, domain, count, rng, nullptr);
  if (!flowVorticity) throw std::invalid_argument("seedVortexParticles: LocalFlow seeding needs the grid's vorticity");
  if (!(flowVorticity->spec() == domain && flowVorticity->size() == domain.res))
    throw std::invalid_argument("seedVortexParticles: the vorticity grid is not cell-centred on the domain");
  const FlowVorticitySampler<D> flow = [&](const std::vector<Vec<D>>& positions, std::vector<VortexVector<D>>& out) {
    out.resize(positions.size());
    for (std::size_t n = 0; n < positions.size(); ++n) out[n] = flowVorticityAt<D>(*flowVorticity, positions[n]);
  };
  return seed<D>(particles, settings, domain, count, rng, &flow);
}

template <int D>
std::size_t seedVortexParticles(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings,
                                const GridSpec<D>& domain, std::size_t count, Rng& rng,
                                const FlowVorticitySampler<D>& flow) {
  return seed<D>(particles, settings, domain, count, rng, &flow);
}

namespace {

template <int D>
std::size_t seed(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings, const GridSpec<D>& domain,
                 std::size_t count, Rng& rng, const FlowVorticitySampler<D>* flow) {
  settings.validate(domain);
  const auto position = [&] {
    Vec<D> x;
    for (int a = 0; a < D; ++a) x[a] = rng.uniform(settings.regionMin[a], settings.regionMax[a]);
    return Vec<D>(x.template cast<float>().template cast<double>());  // the stored position, so omega fits it exactly
  };
  particles.reserve(particles.size() + count);
  std::size_t added = 0;
  if (settings.vorticity == SeedVorticity::LocalFlow) {
    // The positions only are drawn, then the flow read at all of them (a split run reads them on
    // the owning ranks with one reduction); no particle where the flow is too calm.
    std::vector<Vec<D>> positions(count);
    for (auto& x : positions) x = position();
    std::vector<VortexVector<D>> omega;
    (*flow)(positions, omega);
    for (std::size_t n = 0; n < count; ++n) {
      if (!(omega[n].norm() > settings.minimumFlowVorticity)) continue;
      particles.add(positions[n], omega[n], settings.radius, settings.strength);
      ++added;
    }
    return added;
  }
  const Vec<D> centre = 0.5 * (settings.regionMin + settings.regionMax);
  for (std::size_t n = 0; n < count; ++n) {
    const Vec<D> x = position();
    VortexVector<D> omega;
    switch (settings.vorticity) {
      case SeedVorticity::Random:
        omega = settings.magnitude * randomDirection<D>(rng);
        break;
      case SeedVorticity::Azimuthal: {
        VortexVector<D> t = azimuthalDirection<D>(x, centre, settings.upAxis);
        if (t.squaredNorm() == 0.0) t = randomDirection<D>(rng);  // exactly on the axis
        omega = settings.magnitude * t;
        break;
      }
      case SeedVorticity::Vertical: {
        const double sign = rng.uniform() < 0.5 ? -1.0 : 1.0;
        if constexpr (D == 3) {
          omega = VortexVector<D>::Zero();
          omega[settings.upAxis] = sign * settings.magnitude;
        } else {
          omega = VortexVector<D>(sign * settings.magnitude);
        }
        break;
      }
      case SeedVorticity::LocalFlow:
        break;  // above
    }
    particles.add(x, omega, settings.radius, settings.strength);
    ++added;
  }
  return added;
}

}  // namespace

template <int D>
VortexEmitter<D>::VortexEmitter(const VortexSeedSettings<D>& settings, const GridSpec<D>& domain, double rate,
                                std::uint64_t seed, const std::string& context)
    : settings_(settings), domain_(domain), rate_(rate), root_(seed) {
  settings.validate(domain, context);
  if (!(std::isfinite(rate) && rate >= 0.0))
    fail(context, "rate", "particles per second must be finite and >= 0, got " + std::to_string(rate));
}

template <int D>
std::size_t VortexEmitter<D>::due(double dt, Rng& rng) {
  requireValidVortexTimestep(dt, "VortexEmitter::emit");
  carry_ += rate_ * dt;
  const double whole = std::floor(carry_);
  carry_ -= whole;
  rng = root_.split(calls_++);
  return static_cast<std::size_t>(whole);
}

template <int D>
std::size_t VortexEmitter<D>::emit(VortexParticles<D>& particles, double dt, const Vorticity<D>* flowVorticity) {
  Rng rng = root_;
  const std::size_t count = due(dt, rng);
  return seedVortexParticles<D>(particles, settings_, domain_, count, rng, flowVorticity);
}

template <int D>
std::size_t VortexEmitter<D>::emit(VortexParticles<D>& particles, double dt, const FlowVorticitySampler<D>& flow) {
  Rng rng = root_;
  const std::size_t count = due(dt, rng);
  return seedVortexParticles<D>(particles, settings_, domain_, count, rng, flow);
}

template struct VortexSeedSettings<2>;
template struct VortexSeedSettings<3>;
template class VortexEmitter<2>;
template class VortexEmitter<3>;
template std::size_t seedVortexParticles<2>(VortexParticles<2>&, const VortexSeedSettings<2>&, const GridSpec<2>&,
                                            std::size_t, Rng&, const Vorticity<2>*);
template std::size_t seedVortexParticles<3>(VortexParticles<3>&, const VortexSeedSettings<3>&, const GridSpec<3>&,
                                            std::size_t, Rng&, const Vorticity<3>*);
template std::size_t seedVortexParticles<2>(VortexParticles<2>&, const VortexSeedSettings<2>&, const GridSpec<2>&,
                                            std::size_t, Rng&, const FlowVorticitySampler<2>&);
template std::size_t seedVortexParticles<3>(VortexParticles<3>&, const VortexSeedSettings<3>&, const GridSpec<3>&,
                                            std::size_t, Rng&, const FlowVorticitySampler<3>&);
template VortexVector<2> flowVorticityAt<2>(const Vorticity<2>&, const Vec<2>&);
template VortexVector<3> flowVorticityAt<3>(const Vorticity<3>&, const Vec<3>&);

}  // namespace msim::fluid
