#pragma once
// The machinery that procedural sub-grid turbulence (Narain 2011, ch. 3) shares between the
// phenomena it details (smoke's scalars, ch. 3.5.2; a liquid's surface, ch. 3.5.3): the energy
// model on the simulation grid, the noise particles, u' synthesised on a grid `refinement` times
// finer in the band the phenomenon asks for, the solids on both grids, and fine fields carried by
// U + u' in a box round the band. The phenomenon's own class runs a step as
//   stepEnergy (eq. 3.5), [its own changes to E_0], synthesize (particles, band, u'), advect
// and keeps what lives on the fine grid (smoke's density and temperature, the liquid's surface).
#include <cstdint>
#include <initializer_list>
#include <memory>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/turbulence/fine_advection.hpp"
#include "msim/turbulence/noise_particles.hpp"
#include "msim/turbulence/turbulence_band.hpp"
#include "msim/turbulence/turbulent_energy.hpp"

namespace msim::turbulence {

struct SubgridTurbulenceParams {
  int refinement = 4;  // fine cells per simulation cell and axis (the seed: 4)
  TurbulentEnergyParams energy;  // l_0 <= 0: four simulation cells
  NoiseParticleParams particles;
};

template <int D>
class SubgridTurbulence {
 public:
  // coarseSolid: the simulation's solid mask (> 0.5) or null; each fine cell takes the coarse cell
  // it lies in. std::invalid_argument for refinement < 1.
  SubgridTurbulence(const GridSpec<D>& coarse, const SubgridTurbulenceParams& params,
                    const numerics::AdvectionSettings& advection, const Grid<float, D>* coarseSolid);

  // Moving obstacles: the simulation's new solid mask; the fine grid, the energy model, the fine
  // advection and the noise particles follow it.
  void setSolid(const Grid<float, D>& coarseSolid);
  // Restarts the noise particles (a resumed run: they are not saved).
  void reseedParticles();

  // Eq. 3.5 in the simulation's velocity U over dt.
  void stepEnergy(const MacGrid<D>& velocity, double dt);
  // The noise particles move with U; the band grows from `seeds` (a flag per simulation cell);
  // u' on its fine faces. energyFloor (simulation cells, or null): E_0 taken as at least this.
  void synthesize(const MacGrid<D>& velocity, double dt, const std::vector<std::uint8_t>& seeds,
                  const Grid<float, D>* energyFloor = nullptr);
  // The fields (grids over the fine spec) carried by U + u' (turbulent false: by U alone) over dt
  // in the fine box round the band; nothing when the band is empty.
  void advect(std::initializer_list<Grid<float, D>*> fields, const MacGrid<D>& velocity, double dt,
              bool turbulent = true);

  const GridSpec<D>& coarseSpec() const { return coarse_; }
  const GridSpec<D>& fineSpec() const { return fine_; }
  int refinement() const { return params_.refinement; }
  bool hasSolid() const { return hasSolid_; }
  const Grid<float, D>& coarseSolid() const { return coarseSolid_; }
  const Grid<float, D>& fineSolid() const { return fineSolid_; }
  TurbulentEnergy<D>& energy() { return energy_; }
  const TurbulentEnergy<D>& energy() const { return energy_; }
  const NoiseParticles<D>& particles() const { return *particles_; }
  const MacGrid<D>& turbulentVelocity() const { return turbulent_; }  // u' on the fine faces
  const TurbulenceBand<D>& band() const { return band_; }
  // The fine box advect() works in: fine cells [lo, hi) (equal when the band is empty).
  IVec<D> boxLo() const { return band_.lo() * params_.refinement; }
  IVec<D> boxHi() const { return band_.hi() * params_.refinement; }
  // U resampled onto the fine faces plus the last u' (for outputs).
  MacGrid<D> fineVelocity(const MacGrid<D>& velocity) const;

 private:
  GridSpec<D> coarse_, fine_;
  SubgridTurbulenceParams params_;
  Grid<float, D> coarseSolid_, fineSolid_;
  bool hasSolid_ = false;
  MacGrid<D> turbulent_;
  TurbulenceBand<D> band_;
  TurbulentEnergy<D> energy_;
  std::unique_ptr<NoiseParticles<D>> particles_;
  FineAdvection<D> fineAdvection_;
};

extern template class SubgridTurbulence<2>;
extern template class SubgridTurbulence<3>;

}  // namespace msim::turbulence
