#pragma once
// Vortex particles as a layer of a grid fluid (Selle ch. 3.3-3.5): the particles, their source
// and their kernel, and the two calls the grid solver makes in its step:
//   addForce  at the body forces (step 2 of the pressure-velocity solver): u += dt sum_p F_p;
//   advance   after the projection: the particles move with the divergence-free velocity
//             (advection), their vorticity turns with its gradient (stretching with rescale),
//             those inside solids are deleted or pushed out, those that left the domain are
//             dropped, and the source adds new ones (at `rate` while start <= t < end).
// Used by smoke now and by liquids and the velocity-vorticity decomposition later.
#include <cstdint>
#include <limits>
#include <optional>
#include <string>
#include <vector>

#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"
#include "msim/fluid/vortex/vortex_seeding.hpp"

namespace msim::fluid {

enum class VortexSolidHandling { Delete, PushOut };

template <int D>
struct VortexLayerSettings {
  VortexKernel kernel = VortexKernel::ClampedGaussian;
  VortexSeedSettings<D> seed;  // region, vorticity, magnitude, radius, strength
  double rate = 0.0;           // particles per second while seeding
  std::size_t initialCount = 0;  // particles seeded at the start
  double start = 0.0, end = std::numeric_limits<double>::infinity();  // seeding window [s]
  VortexSolidHandling solids = VortexSolidHandling::Delete;  // Fig. 3.5 deletes
  std::uint64_t randomSeed = 1;
};

template <int D>
class VortexLayer {
 public:
  // std::invalid_argument naming `context` (the scene key) for settings the seeding refuses, a
  // negative rate, or an empty or inverted seeding window.
  VortexLayer(const VortexLayerSettings<D>& settings, const GridSpec<D>& domain, const std::string& context);

  void addForce(MacGrid<D>& velocity, double dt, const Grid<float, D>* solidMask) const;
  // flowVorticity: the grid's vorticity, needed when the seed takes the local flow's.
  void advance(const MacGrid<D>& velocity, double dt, double time, const Vorticity<D>* flowVorticity);
  // The obstacles as a signed distance at the grid nodes (negative inside), copied; none before.
  void setSolid(const Grid<float, D>& nodalSolidPhi) { solidPhi_ = nodalSolidPhi; }
  // The particles seeded at the start (initialCount), once; flowVorticity as for advance.
  void seedInitial(const Vorticity<D>* flowVorticity);
  // Deletes the particles where `field` (cell-centred over the solver's grid, a block with ghosts
  // in a split run; read D-linearly, on the owning rank) is positive: a liquid's phi deletes those
  // in the air. Returns how many.
  std::size_t removeWherePositive(const Grid<float, D>& field);
  // Runs the layer on one block of a split domain (Selle ch. 8; null: the whole domain): the
  // velocity, solid mask and signed distance it is given are then the block's (with ghosts).
  // Every rank keeps every particle and moves them alike: the rank whose owned cells hold a
  // particle reads the flow (and the solid) there, and the ranks sum what they read, one reduction
  // per read; seeding with the local flow's vorticity reads it so at the drawn positions. Set it
  // before seedInitial.
  void setDomainSplit(DomainSplit<D>* split);

  const VortexParticles<D>& particles() const { return particles_; }
  VortexParticles<D>& particles() { return particles_; }
  const VortexLayerSettings<D>& settings() const { return settings_; }
  bool needsFlowVorticity() const { return settings_.seed.vorticity == SeedVorticity::LocalFlow; }
  // The grid's vorticity of `velocity` when the seeding takes the local flow's (kept in the layer,
  // computed anew per call), else null: what advance and seedInitial want.
  const Vorticity<D>* flowVorticity(const MacGrid<D>& velocity);

 private:
  VortexLayerSettings<D> settings_;
  GridSpec<D> domain_;
  VortexParticles<D> particles_;
  VortexEmitter<D> emitter_;
  // The split run's advance: reads on the owning rank, summed over the ranks.
  void advanceSplit(const MacGrid<D>& velocity, double dt);
  // Whether the block owns the cell holding world position x (cell indices clamped to the global
  // domain, so a particle on its border has an owner).
  bool owns(const GridSpec<D>& local, const Vec<D>& x) const;
  // reads_ = `width` numbers per position: read(position, index, out) on the rank that owns the
  // position, zeros elsewhere, summed over the ranks; readAtOwners: at the particles.
  template <typename PositionOf, typename Read>
  void readAt(const GridSpec<D>& local, std::size_t count, PositionOf&& positionOf, std::size_t width, Read&& read);
  template <typename Read>
  void readAtOwners(const GridSpec<D>& local, std::size_t width, Read&& read);
  // The split run's LocalFlow seeding: the block's vorticity `local` read on the owning ranks.
  FlowVorticitySampler<D> flowAtOwners(const Vorticity<D>* local);

  std::optional<Grid<float, D>> solidPhi_;
  std::optional<Vorticity<D>> flowVorticity_;
  DomainSplit<D>* split_ = nullptr;
  BlockPlacement<D> placement_;  // the block's place, and its own cells, in a split run
  IndexBox<D> owned_;
  std::vector<double> reads_;  // the split run's per-particle reads, summed over the ranks
};

}  // namespace msim::fluid
