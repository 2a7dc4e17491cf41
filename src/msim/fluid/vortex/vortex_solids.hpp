#pragma once
// Vortex particles that enter solid geometry (Selle ch. 3.4.1): "we could delete them or project
// them back out of the object using an object level set. Since we use a high density of particles
// (typically thousands), either option suffices." Fig. 3.5 deletes them.
//
// The solid is a signed distance, negative inside: any callable phi(Vec<D>) -> double, or a sampled
// Grid<float, D> (any sample layout, read D-linearly; e.g. the nodal phi of SmokeSolver).
#include <cmath>
#include <cstddef>
#include <optional>
#include <stdexcept>

#include "msim/core/grid.hpp"
#include "msim/core/interpolation.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"

namespace msim::fluid {

struct SolidPushOutResult {
  std::size_t pushed = 0;   // moved out of the solid
  std::size_t deleted = 0;  // could not be moved out (no gradient, or still inside after the push)
};

// Deletes every particle with phi(x_p) < 0; returns how many.
template <int D, typename SignedDistance>
std::size_t removeVortexParticlesInSolid(VortexParticles<D>& particles, const SignedDistance& phi) {
  const auto& x = particles.positions();
  return particles.removeIf([&](std::size_t p) { return phi(Vec<D>(x[p].template cast<double>())) < 0.0; });
}

// One particle at y inside the solid (phi(y) < 0) moved along the level set's normal
// n = grad phi / |grad phi| (central differences with step h) to phi = clearance:
// y <- y + (clearance - phi) n, repeated up to three times for a distance that is not exact. Its
// new place, or none where it is still inside or the gradient vanishes (it is to be deleted).
template <int D, typename SignedDistance>
std::optional<Vec<D>> pushedOutOfSolid(const SignedDistance& phi, Vec<D> y, double h, double clearance) {
  double d = phi(y);
  for (int iteration = 0; iteration < 3 && d < clearance; ++iteration) {
    Vec<D> g;
    for (int a = 0; a < D; ++a) {
      Vec<D> up = y, down = y;
      up[a] += h;
      down[a] -= h;
      g[a] = (phi(up) - phi(down)) / (2.0 * h);
    }
    const double norm = g.norm();
    if (!(norm > 0.0)) break;
    y += (clearance - d) * (g / norm);
    d = phi(y);
  }
  if (!(d >= 0.0)) return std::nullopt;
  return y;
}

// Moves every particle with phi(x_p) < 0 out of the solid (pushedOutOfSolid); one that cannot be
// moved out is deleted. std::invalid_argument unless h > 0 and clearance >= 0.
template <int D, typename SignedDistance>
SolidPushOutResult pushVortexParticlesOutOfSolid(VortexParticles<D>& particles, const SignedDistance& phi, double h,
                                                 double clearance) {
  if (!(std::isfinite(h) && h > 0.0))
    throw std::invalid_argument("pushVortexParticlesOutOfSolid: the difference step must be > 0 m, got " + std::to_string(h));
  if (!(std::isfinite(clearance) && clearance >= 0.0))
    throw std::invalid_argument("pushVortexParticlesOutOfSolid: the clearance must be >= 0 m, got " + std::to_string(clearance));
  SolidPushOutResult result;
  auto& x = particles.positions();
  // The predicate writes the pushed position of particle p before removeIf moves p down, so the
  // survivors keep their new positions.
  const std::size_t deleted = particles.removeIf([&](std::size_t p) {
    const Vec<D> y = x[p].template cast<double>();
    if (!(phi(y) < 0.0)) return false;
    const std::optional<Vec<D>> out = pushedOutOfSolid<D>(phi, y, h, clearance);
    if (!out) return true;
    x[p] = out->template cast<float>();
    ++result.pushed;
    return false;
  });
  result.deleted = deleted;
  return result;
}

// The same for a sampled signed distance (negative inside), D-linear; h defaults to half a cell.
template <int D>
std::size_t removeVortexParticlesInSolid(VortexParticles<D>& particles, const Grid<float, D>& phi) {
  return removeVortexParticlesInSolid<D>(particles, [&](const Vec<D>& y) { return double(sampleLinear<D>(phi, y)); });
}
template <int D>
SolidPushOutResult pushVortexParticlesOutOfSolid(VortexParticles<D>& particles, const Grid<float, D>& phi,
                                                 double clearance) {
  return pushVortexParticlesOutOfSolid<D>(
      particles, [&](const Vec<D>& y) { return double(sampleLinear<D>(phi, y)); }, 0.5 * phi.spec().dx, clearance);
}

}  // namespace msim::fluid
