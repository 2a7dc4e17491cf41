#pragma once
// Sub-grid turbulence at a liquid's free surface (Narain 2011, ch. 3.5.3): the liquid solver keeps
// the large scales U and its own surface on the simulation grid; the energy model tracks the
// sub-grid energy there, noise particles synthesise u' on a grid `refinement` times finer, and a
// fine level set phi, carried by U + u', shows ripples the simulation grid cannot hold. Two effects
// keep the ripples alive and make them die out (ch. 3.5.3):
//   relaxation (eq. 3.13): phi <- phi + dt / tau' (phi~ - phi), phi~ the surface without sub-grid
//     features, tau' = dx / c with c = sqrt(g dx / (2 pi)) the speed of deep-water gravity waves of
//     the simulation cell's wavelength;
//   ripple energy (eq. 3.14): E' = (delta / tau')^2, delta the mean |phi - phi~| over the fine
//     cells near the surface in each simulation cell; the noise uses max(E_0, E') (noise_particles.hpp).
//
// Departure from the seed, for a reason: the seed makes the fine surface the liquid (the simulation
// grid's level set is the fine one filtered and downsampled; a cell is liquid if any fine liquid is
// in it, with a variable-density projection over the fill fractions). Here the simulation keeps its
// own tracker (particle level set or FLIP, which hold the volume, docs/liquid.md) and phi~ is that
// tracker's level set resampled onto the fine cells; the fine surface is a detail layer tied to it
// by eq. 3.13. The simulation does not feel the ripples, as in the seed, and U is not advected by
// U + u' (the smoke's coupling of ch. 3.5.2).
//
// One step, after the liquid solver's step (its new velocity U and level set):
//   1. the energy model (eq. 3.5) in U; air cells more than kAirCells from the surface hold none
//      (their velocity is the extrapolation's, or zero beyond it);
//   2. noise particles move with U;
//   3. the band: simulation cells within kSurfaceCells of the surface, grown by the step's reach
//      (turbulence_band.hpp);
//   4. u' on the band's fine faces from max(E_0, E');
//   5. in a box round the band, the detail eta = phi - phi~ as U + u' carries phi and U alone
//      carries phi~: eta advected by U + u', less dt u' . grad phi~ (the first-order difference
//      of carrying phi~ by the two);
//   6. eq. 3.13: phi = phi~ + (1 - dt / tau') eta with phi~ the tracker's new surface (outside the
//      box phi = phi~), so what the tracker does beyond carrying its surface (particle corrections,
//      emitters, sinks, volume control) shows at once;
//   7. delta and E' for the next step.
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/timer.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/turbulence/subgrid_turbulence.hpp"

namespace msim::fluid {

// refinement, energy and particles: the shared model (turbulence/subgrid_turbulence.hpp).
struct LiquidTurbulenceParams : turbulence::SubgridTurbulenceParams {
  double gravity = 9.81;  // |g| [m/s^2]: the ripples' wave speed c
};

template <int D>
class LiquidTurbulence {
 public:
  static constexpr double kSurfaceCells = 1.0;  // simulation cells either side of the surface that get u' (the detail is held within one)
  static constexpr double kAirCells = 2.0;      // air this far from the surface keeps turbulent energy

  // coarsePhi: the simulation's level set (phi starts as it, resampled); coarseSolid: its solid
  // mask or null. std::invalid_argument for refinement < 1 or gravity <= 0.
  LiquidTurbulence(const GridSpec<D>& coarse, const LiquidTurbulenceParams& params,
                   const numerics::AdvectionSettings& advection, const Grid<float, D>& coarsePhi,
                   const Grid<float, D>* coarseSolid);

  // After the liquid solver's step: steps 1-7 above.
  void step(const MacGrid<D>& velocity, const Grid<float, D>& coarsePhi, double dt);
  // The fine surface without ripples: phi = phi~ (the start; E' then starts from zero).
  void resetSurface(const Grid<float, D>& coarsePhi);
  // Moving obstacles: the simulation grid's new solid mask.
  void setSolid(const Grid<float, D>& coarseSolid) { model_.setSolid(coarseSolid); }
  // Restarts the noise particles (a resumed run: they are not saved).
  void reseedParticles() { model_.reseedParticles(); }

  const GridSpec<D>& fineSpec() const { return model_.fineSpec(); }
  const Grid<float, D>& phi() const { return phi_; }     // the fine surface
  // A saved fine surface (a resumed run): its detail against phi~ of the simulation's coarsePhi.
  void restoreSurface(const Grid<float, D>& finePhi, const Grid<float, D>& coarsePhi);
  const Grid<float, D>& fineSolid() const { return model_.fineSolid(); }
  const Grid<float, D>& rippleEnergy() const { return ripple_; }  // E' on the simulation cells
  double relaxationTime() const { return tau_; }                  // tau' [s]
  double meanRippleHeight() const { return meanDelta_; }          // delta over the surface cells [m]
  turbulence::TurbulentEnergy<D>& energy() { return model_.energy(); }
  const turbulence::TurbulentEnergy<D>& energy() const { return model_.energy(); }
  const turbulence::NoiseParticles<D>& particles() const { return model_.particles(); }
  const MacGrid<D>& turbulentVelocity() const { return model_.turbulentVelocity(); }  // u' on the fine faces
  double bandFraction() const { return model_.band().fraction(); }
  const LiquidTurbulenceParams& params() const { return params_; }
  // Seconds per stage: energy (step 1), noise (2-4), surface advection (5), surface relaxation (6-7).
  const StageTimers& timers() const { return timers_; }
  void resetTimers() { timers_.reset(); }

 private:
  void relax(const Grid<float, D>& coarsePhi, double dt);
  void subtractEddyTransport(double dt);
  void measureRipples(const Grid<float, D>& coarsePhi);

  LiquidTurbulenceParams params_;
  double tau_;
  turbulence::SubgridTurbulence<D> model_;
  GridSpec<D> coarse_, fine_;
  Grid<float, D> phi_, smoothed_, detail_;  // phi, phi~ and eta = phi - phi~ on the fine cells
  Grid<float, D> ripple_;          // E' on the simulation cells
  std::vector<std::uint8_t> seeds_;
  std::vector<double> delta_;      // measureRipples: delta per simulation cell (-1: not at the surface)
  IVec<D> boxLo_ = IVec<D>::Zero(), boxHi_ = IVec<D>::Zero();  // the advected fine box [lo, hi)
  double meanDelta_ = 0.0;
  StageTimers timers_;
};

extern template class LiquidTurbulence<2>;
extern template class LiquidTurbulence<3>;

}  // namespace msim::fluid
