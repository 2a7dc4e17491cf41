#include "msim/turbulence/subgrid_turbulence.hpp"

#include <stdexcept>

#include "msim/core/parallel.hpp"

namespace msim::turbulence {

namespace {

template <int D>
GridSpec<D> refined(const GridSpec<D>& coarse, int r) {
  if (r < 1) throw std::invalid_argument("sub-grid turbulence: the refinement must be >= 1");
  return GridSpec<D>(coarse.origin, coarse.dx / r, coarse.res * r);
}

}  // namespace

template <int D>
SubgridTurbulence<D>::SubgridTurbulence(const GridSpec<D>& coarse, const SubgridTurbulenceParams& params,
                                        const numerics::AdvectionSettings& advection, const Grid<float, D>* coarseSolid)
    : coarse_(coarse),
      fine_(refined(coarse, params.refinement)),
      params_(params),
      coarseSolid_(coarse, 0.0f),
      fineSolid_(fine_, 0.0f),
      turbulent_(fine_),
      band_(coarse, params.refinement),
      energy_(coarse, params.energy),
      fineAdvection_(fine_, advection) {
  if (coarseSolid) setSolid(*coarseSolid);
  reseedParticles();
}

template <int D>
void SubgridTurbulence<D>::setSolid(const Grid<float, D>& coarseSolid) {
  coarseSolid_ = coarseSolid;
  hasSolid_ = true;
  const int r = params_.refinement;
  parallelForCells<D>(fine_.res, [&](const IVec<D>& c, std::size_t lin) { fineSolid_[lin] = coarseSolid_(IVec<D>(c / r)); });
  energy_.setSolid(coarseSolid_);
  fineAdvection_.setSolid(fineSolid_);
  if (particles_) particles_->setSolid(coarseSolid_);
}

template <int D>
void SubgridTurbulence<D>::reseedParticles() {
  particles_ = std::make_unique<NoiseParticles<D>>(coarse_, energy_, fine_.dx, params_.particles,
                                                   hasSolid_ ? &coarseSolid_ : nullptr);
}

template <int D>
void SubgridTurbulence<D>::stepEnergy(const MacGrid<D>& velocity, double dt) {
  energy_.step(velocity, dt);
}

template <int D>
void SubgridTurbulence<D>::synthesize(const MacGrid<D>& velocity, double dt, const std::vector<std::uint8_t>& seeds,
                                      const Grid<float, D>* energyFloor) {
  particles_->advance(velocity, energy_, dt, energyFloor);
  band_.mark(seeds, velocity, dt);
  particles_->synthesize(energy_, turbulent_, &band_.nodeWeight(), energyFloor);
}

template <int D>
void SubgridTurbulence<D>::advect(std::initializer_list<Grid<float, D>*> fields, const MacGrid<D>& velocity, double dt,
                                  bool turbulent) {
  if (band_.empty()) return;
  fineAdvection_.advect(fields, boxLo(), boxHi() - boxLo(), velocity, turbulent ? &turbulent_ : nullptr, dt);
}

template <int D>
MacGrid<D> SubgridTurbulence<D>::fineVelocity(const MacGrid<D>& velocity) const {
  MacGrid<D> out(fine_);
  turbulentAdvectingVelocity<D>(velocity, &turbulent_, IVec<D>::Zero(), out);
  return out;
}

template class SubgridTurbulence<2>;
template class SubgridTurbulence<3>;

}  // namespace msim::turbulence
