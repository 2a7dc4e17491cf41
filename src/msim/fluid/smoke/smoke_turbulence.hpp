#pragma once
// Procedural turbulence for smoke (Narain 2011, ch. 3): the coarse smoke solver keeps the large
// scales U; the energy model tracks the sub-grid turbulent energy on the coarse grid; noise
// particles synthesise the turbulent velocity u' on a grid `refinement` times finer; density and
// temperature live on that fine grid and are carried by U + u' (ch. 3.5.2), so the smoke shows
// eddies the coarse grid cannot hold. The coarse solver sees the scalars downsampled (for its
// buoyancy) and, with coupling on, advects U by U + u' averaged onto its faces (ch. 3.5.2).
//
// One step, in the order of the coarse solver's own (sources, velocity, scalars advected by the new
// velocity):
//   SmokeTurbulence::applySources, before the coarse solver's step: the fine sources, and the
//   scalars averaged onto the coarse cells, so the step's buoyancy sees this step's heat;
//   SmokeTurbulence::step, after it, with its new velocity U:
//   1. energy model (eq. 3.5) in U; 2. noise particles move with U, noise times advance;
//   3. the active cells: coarse cells with smoke (more than the threshold) or heat, grown by one
//      cell and by the distance the flow carries it in a step, and a taper of two cells beyond;
//   4. u' on the fine faces of the active cells, its potential weighted down to zero across the
//      taper;
//   5. the fine scalars advected by U (interpolated) + u' in a window round the active cells
//      (fainter smoke outside it stays where it is), and dissipated (the coarse solver, told that
//      its scalars are carried here, neither advects nor dissipates them);
//   6. the scalars averaged onto the coarse cells, u' onto the coarse faces (flux averages, so the
//      coarse u' stays divergence-free) for the next step's coupling.
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/fluid/smoke/smoke_solver.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/turbulence/subgrid_turbulence.hpp"

namespace msim::fluid {

// refinement, energy and particles: the shared model (turbulence/subgrid_turbulence.hpp).
struct SmokeTurbulenceParams : turbulence::SubgridTurbulenceParams {
  bool coupling = true;            // U advected by U + u' (ch. 3.5.2)
  double smokeThreshold = 1e-4;    // [kg/m^3] coarse cells with less smoke get no u'
  bool writeVelocity = false;      // the scene writes U + u' on the fine grid as its "vel" (outputs only)
  double densityDissipation = 0.0, temperatureDissipation = 0.0;  // [1/s] the smoke's decay (SmokeParams)
};

template <int D>
class SmokeTurbulence {
 public:
  // coarseSolid: the solver's solid mask (or null); the fine grid takes each fine cell from the
  // coarse cell it lies in. std::invalid_argument for refinement < 1.
  SmokeTurbulence(const GridSpec<D>& coarse, const SmokeTurbulenceParams& params,
                  const numerics::AdvectionSettings& advection, const Grid<float, D>* coarseSolid,
                  double ambientTemperature);

  // A source on the fine grid (cells of fineSpec()): its density and temperature (inflow velocities
  // act on the coarse solver). std::invalid_argument if it carries extra scalars (fuel): they live
  // on the simulation grid.
  void addSource(SmokeSource<D> source);
  SmokeSource<D>& source(std::size_t i) { return sources_[i]; }

  // Before the coarse solver's step: the fine sources; coarseDensity and coarseTemperature receive
  // the averaged fine scalars.
  void applySources(double dt, Grid<float, D>& coarseDensity, Grid<float, D>& coarseTemperature);
  // After the coarse solver's step, with its new velocity: steps 1-6 above; coarseDensity and
  // coarseTemperature receive the averaged fine scalars.
  void step(const MacGrid<D>& velocity, double dt, Grid<float, D>& coarseDensity, Grid<float, D>& coarseTemperature);

  const GridSpec<D>& fineSpec() const { return model_.fineSpec(); }
  const Grid<float, D>& fineSolid() const { return model_.fineSolid(); }
  Grid<float, D>& density() { return density_; }
  const Grid<float, D>& density() const { return density_; }
  Grid<float, D>& temperature() { return temperature_; }
  const Grid<float, D>& temperature() const { return temperature_; }
  const MacGrid<D>& turbulentVelocity() const { return model_.turbulentVelocity(); }  // u' on the fine faces
  // U interpolated onto the fine faces plus the last step's u' (for outputs).
  MacGrid<D> fineVelocity(const MacGrid<D>& velocity) const { return model_.fineVelocity(velocity); }
  const MacGrid<D>& coarseTurbulentVelocity() const { return coarseTurbulent_; }  // u' on the coarse faces
  turbulence::TurbulentEnergy<D>& energy() { return model_.energy(); }
  const turbulence::TurbulentEnergy<D>& energy() const { return model_.energy(); }
  const turbulence::NoiseParticles<D>& particles() const { return model_.particles(); }
  const SmokeTurbulenceParams& params() const { return params_; }
  // Moving obstacles: the simulation grid's new solid mask; the fine grid, the energy model, the
  // fine advector and the noise particles follow it.
  void setSolid(const Grid<float, D>& coarseSolid);
  // Restarts the noise particles (a resumed run: they are not saved).
  void reseedParticles() { model_.reseedParticles(); }
  // Fills the coarse grids with the fine scalars averaged (after a restore).
  void downsample(Grid<float, D>& coarseDensity, Grid<float, D>& coarseTemperature) const;
  // 1/2 int |u'|^2 dV over the fine grid [m^5/s^2] (per unit depth in 2D), from the face values.
  double turbulentKineticEnergy() const;
  // Fraction of the fine nodes that got a potential in the last step.
  double bandFraction() const { return model_.band().fraction(); }

 private:
  // Smoke does not live inside solids.
  void clearSmokeInSolids();
  // seeds_: the coarse cells with smoke (more than the threshold) or heat, where the band grows from.
  void markSeeds(const Grid<float, D>& coarseDensity, const Grid<float, D>& coarseTemperature);
  void averageTurbulenceToCoarse();

  SmokeTurbulenceParams params_;
  double ambientTemperature_;
  turbulence::SubgridTurbulence<D> model_;
  Grid<float, D> density_, temperature_;
  MacGrid<D> coarseTurbulent_;
  std::vector<std::uint8_t> seeds_;  // coarse cells with smoke or heat (markBand)
  std::vector<SmokeSource<D>> sources_;
};

extern template class SmokeTurbulence<2>;
extern template class SmokeTurbulence<3>;

}  // namespace msim::fluid
