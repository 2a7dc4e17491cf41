#pragma once
// Noise particles (Narain 2011 ch. 3.5.1): the turbulent velocity u' as the curl of a potential
// carried by particles that move with the mean flow, so the eddies travel with the fluid without
// being distorted by it. Each particle j carries an offset o_j into the animated noise tile and a
// noise time t_ij per octave i; octave i of the potential is the weighted average of eq. 3.12
//   psi_i(x) = sum_j rho(|x - p_j|) A_i(p_j) N(o_j + (x - p_j) / l_i, t_ij) / sum_j rho(|x - p_j|)
// with rho(r) = 1 - 3 (r/l_0)^2 + 2 (r/l_0)^3 (r < l_0), l_i = l_0 / 2^i and A_i = s sqrt(E_i) l_i,
// E_i the octave's energy from the energy model (eq. 3.4, 3.10) and s the user's intensity (1: the
// seed). One particle's noise then has eddy speeds of rms sqrt(E_i) ("magnitude u_i = sqrt(E_i)",
// ch. 3.3-3.5; the tile's scale, curl_noise.hpp); the average of eq. 3.12 lowers the variance
// where particles overlap (to about a third where four do), so 1/2 <|u'|^2> comes out below E_i:
// the seed's calibration, kept because a variance-preserving blend that gives 1/2 <|u'|^2> = E_i
// made the plume of Fig. 3.6 far too turbulent (docs/turbulence.md). The noise time advances by
// 1 / tau_i per second, tau_i = l_i / sqrt(E_i) the eddy turnover time. u' = curl sum_i psi_i on the
// faces of a finer grid, divergence-free to round-off (curl_noise.hpp).
//
// Departures from the seed, each for a reason:
// - The seed samples a Poisson disk of spacing l_0 once and notes that dynamic resampling was not
//   needed; with open boundaries particles leave, so here cells of side l_0 without a particle get
//   one each step (and particles beyond three per cell are dropped where the flow converges).
// - The seed's Perlin noise is replaced by the band-limited NoiseTile.
#include <array>
#include <cstdint>
#include <optional>
#include <vector>

#include <tbb/enumerable_thread_specific.h>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/turbulence/curl_noise.hpp"
#include "msim/turbulence/turbulent_energy.hpp"

namespace msim::turbulence {

struct NoiseParticleParams {
  int octaves = 0;  // 0: every octave whose shortest wavelength l_i / 2 spans two fine cells
  std::uint64_t seed = 0;
  double intensity = 1.0;  // s: multiplies every octave's amplitude (1: the seed's A_i = sqrt(E_i) l_i)
};

template <int D>
class NoiseParticles {
 public:
  static constexpr int kMaxOctaves = 8;

  // Particles over the fluid cells of `coarse` (solid > 0.5 excluded), one per cell of side l_0
  // (energy.largestEddy()), jittered. fineDx: the cell size u' is synthesised at.
  NoiseParticles(const GridSpec<D>& coarse, const TurbulentEnergy<D>& energy, double fineDx,
                 const NoiseParticleParams& params, const Grid<float, D>* solid = nullptr);

  // Moves the particles with U (midpoint rule), advances their noise times by dt / tau_i, removes
  // those that left the domain or entered a solid, and refills empty cells. energyFloor (coarse
  // cells, or null): E_0 is taken as at least this (a liquid's ripple energy, eq. 3.14), here and
  // in synthesize().
  void advance(const MacGrid<D>& velocity, const TurbulentEnergy<D>& energy, double dt,
               const Grid<float, D>* energyFloor = nullptr);

  // u' on the faces of `turbulent` (a MAC grid over the fine spec). nodeWeight (res + 1 per axis, x
  // fastest) multiplies the potential at each node, and nodes of weight 0 are not evaluated; null:
  // every node, weight 1.
  void synthesize(const TurbulentEnergy<D>& energy, MacGrid<D>& turbulent,
                  const std::vector<float>* nodeWeight = nullptr, const Grid<float, D>* energyFloor = nullptr);

  // Moving obstacles: the new solid mask (> 0.5); particles inside it are dropped at the next
  // advance() and empty cells refilled around it.
  void setSolid(const Grid<float, D>& solid) { solid_ = solid; }

  std::size_t size() const { return position_.size(); }
  int octaves() const { return octaves_; }
  const std::vector<Vec<D>>& positions() const { return position_; }

 private:
  void refill(std::uint64_t step);
  // E_0 at x, raised to the floor there when there is one.
  double energyAt(const TurbulentEnergy<D>& energy, const Grid<float, D>* energyFloor, const Vec<D>& x) const;
  bool inFluid(const Vec<D>& x) const;
  IVec<D> coverageCoord(const Vec<D>& x) const;      // the coverage cell holding x (clamped)
  std::size_t coverageIndex(const IVec<D>& c) const;  // x fastest

  GridSpec<D> coarse_;
  double l0_;
  int octaves_;
  NoiseParticleParams params_;
  std::optional<Grid<float, D>> solid_;
  NoiseTile<D> tile_;
  IVec<D> cells_;  // coverage cells of side l_0
  std::vector<Vec<D>> position_, offset_;
  std::vector<std::array<double, kMaxOctaves>> time_;
  std::uint64_t steps_ = 0;
  // synthesis scratch: per particle and octave the amplitude and the noise's time tap; the
  // potential at the fine nodes
  std::vector<std::array<float, kMaxOctaves>> amplitude_;
  std::vector<std::array<LinearTap, kMaxOctaves>> timeTap_;
  std::vector<Vecf<3>> psi_;
  // Per thread: one row of nodes' blended noise, summed weights and falloffs.
  struct RowScratch {
    std::vector<Vecf<3>> acc;
    std::vector<float> weights, rho;
  };
  tbb::enumerable_thread_specific<RowScratch> rowScratch_;
  // The particles are kept in coverage-cell order (refill sorts them): cell c holds
  // [cellStart_[c], cellStart_[c + 1]), which the synthesis's neighbour search reads.
  std::vector<std::uint32_t> cellStart_;
  // refill's scratch, reused from step to step: the old particles by cell (stable counting sort)
  // and the arrays being built.
  std::vector<std::uint32_t> oldCell_, oldStart_, oldOrder_;
  std::vector<Vec<D>> nextPosition_, nextOffset_;
  std::vector<std::array<double, kMaxOctaves>> nextTime_;
};

extern template class NoiseParticles<2>;
extern template class NoiseParticles<3>;

}  // namespace msim::turbulence
