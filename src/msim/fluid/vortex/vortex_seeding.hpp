#pragma once
// Creating vortex particles (Selle ch. 3.4.1 and 3.5): "we typically inject particles with random
// initial vorticity at a uniform rate at a source", or create them "near objects or near
// concentrations of high vorticity, and given the initial vorticity of the surrounding flow".
// Positions are uniform at random in a box. The vorticity is one of
//   Random     |omega_p| = magnitude, direction uniform on the sphere (2D: omega_z = +-magnitude);
//   Azimuthal  |omega_p| = magnitude, tangent to the circles around the vertical line through the
//              box centre: omega_p ~ e_up x (x_p - centre) (Fig. 3.4's explosion: "tangent to the
//              cylinder centered at the source region's midpoint oriented upward"; the sense of
//              rotation is not given, this one spins a rising ring outwards at its top); 2D: the
//              z component of that, +-magnitude on the two sides of the axis;
//   Vertical   omega_p = +-magnitude e_up, the sign at random (Fig. 3.3's river: "vorticity
//              pointing either up or down", eddies about vertical axes); 2D: +-magnitude;
//   LocalFlow  omega_p = the grid's vorticity at x_p (cell-centred, D-linear); no particle where
//              its magnitude is at most minimumFlowVorticity (seeding only where the flow swirls).
// Everything is drawn from a msim::Rng, so a seed gives the same particles on every machine.
#include <cstddef>
#include <cstdint>
#include <functional>
#include <string>
#include <vector>

#include <Eigen/Core>

#include "msim/core/grid.hpp"
#include "msim/core/rng.hpp"
#include "msim/fluid/vortex/grid_vorticity.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"

namespace msim::fluid {


enum class SeedVorticity { Random, Azimuthal, Vertical, LocalFlow };

template <int D>
struct VortexSeedSettings {
  Vec<D> regionMin = Vec<D>::Zero();  // seeding box, lower corner [m]; inside the domain
  Vec<D> regionMax = Vec<D>::Zero();  // upper corner [m]; >= regionMin on every axis
  SeedVorticity vorticity = SeedVorticity::Random;
  double magnitude = 2e-3;  // |omega_p| for Random, Azimuthal and Vertical [1/s] (Fig. 3.4: 2e-3)
  double radius = 0.0;      // kernel radius r_p [m]; > 0 required (the seed uses 3-4 cells, 40 in Fig. 3.3)
  double strength = 1.0;    // eps_p >= 0 (not given by the seed; tuned together with magnitude)
  int upAxis = 1;           // the cylinder's axis for Azimuthal, the direction for Vertical
  double minimumFlowVorticity = 0.0;  // LocalFlow: no particle where |omega_grid| <= this [1/s]

  // std::invalid_argument naming `context` (e.g. the scene key) and the field: a region not inside
  // `domain` or inverted, radius <= 0, strength < 0, magnitude < 0, upAxis out of range, any of
  // them not finite.
  void validate(const GridSpec<D>& domain, const std::string& context = "vortex seeding") const;
};

// The flow's vorticity at each of `positions` (LocalFlow seeding), into `vorticities`: the grid's
// (flowVorticityAt), or in a run split among processes read on the ranks that own the positions.
template <int D>
using FlowVorticitySampler =
    std::function<void(const std::vector<Vec<D>>& positions, std::vector<VortexVector<D>>& vorticities)>;

// The grid's cell-centred vorticity at x, D-linear (clamped at the grid's edges).
template <int D>
VortexVector<D> flowVorticityAt(const Vorticity<D>& grid, const Vec<D>& x);

// Adds `count` particles (fewer for LocalFlow where the flow is too calm) drawn from `rng`;
// flowVorticity is required for LocalFlow (std::invalid_argument without it or when its grid is not
// the domain's). Returns how many were added.
template <int D>
std::size_t seedVortexParticles(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings,
                                const GridSpec<D>& domain, std::size_t count, Rng& rng,
                                const Vorticity<D>* flowVorticity = nullptr);
// The same with the flow's vorticity read by `flow` (LocalFlow: the positions are drawn first, as
// the grid's version draws them, then read at once).
template <int D>
std::size_t seedVortexParticles(VortexParticles<D>& particles, const VortexSeedSettings<D>& settings,
                                const GridSpec<D>& domain, std::size_t count, Rng& rng,
                                const FlowVorticitySampler<D>& flow);

// A source emitting at a uniform rate [particles/s]: each emit(dt) adds floor(carry + rate dt)
// particles and keeps the fraction for the next call, so the count after any sequence of steps is
// floor(rate * total time). Call n draws from Rng(seed).split(n): reproducible whatever the steps.
template <int D>
class VortexEmitter {
 public:
  VortexEmitter(const VortexSeedSettings<D>& settings, const GridSpec<D>& domain, double rate, std::uint64_t seed,
                const std::string& context = "vortex seeding");
  std::size_t emit(VortexParticles<D>& particles, double dt, const Vorticity<D>* flowVorticity = nullptr);
  std::size_t emit(VortexParticles<D>& particles, double dt, const FlowVorticitySampler<D>& flow);
  double rate() const { return rate_; }

 private:
  // The whole particles due after dt more (the fraction carried on), and this call's stream.
  std::size_t due(double dt, Rng& rng);

  VortexSeedSettings<D> settings_;
  GridSpec<D> domain_;
  double rate_;
  double carry_ = 0.0;
  Rng root_;
  std::uint64_t calls_ = 0;
};

}  // namespace msim::fluid
