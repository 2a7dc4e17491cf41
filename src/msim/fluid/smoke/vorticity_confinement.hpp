#pragma once
// Vorticity confinement (Fedkiw, Stam and Jensen 2001; Selle ch. 3.2.1): the curl of the velocity,
// omega = curl u (eq. 3.3), a unit field N = grad|omega| / |grad|omega|| pointing towards
// concentrations of vorticity, and the force f = epsilon dx (N x omega) that spins those
// concentrations back up after numerical dissipation. The dx factor makes the force vanish under
// refinement, where the dissipation it compensates vanishes too.
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/fluid/vortex/grid_vorticity.hpp"

namespace msim::fluid {

// Adds dt * f to the face velocities, with f = epsilon dx (N x omega) at cell centres averaged to
// the faces. The centre velocities, vorticity and force are scratch grids reused between calls
// (no allocation per step). Faces next to solid cells (solid > 0.5, optional) receive no force.
template <int D>
class VorticityConfinement {
 public:
  explicit VorticityConfinement(const GridSpec<D>& spec);
  void apply(MacGrid<D>& velocity, double epsilon, double dt, const Grid<float, D>* solid = nullptr);
  const Vorticity<D>& vorticity() const { return vorticity_; }
  // Force per unit mass at cell centres from the last apply() [m/s^2].
  const Grid<Vecf<D>, D>& force() const { return force_; }

 private:
  Grid<Vecf<D>, D> centre_;
  Vorticity<D> vorticity_;
  Grid<float, D> magnitude_;
  Grid<Vecf<D>, D> force_;
};

}  // namespace msim::fluid
