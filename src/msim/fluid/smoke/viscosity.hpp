#pragma once
// Viscous diffusion of a MAC velocity, du/dt = nu lap u, the viscous term Selle's inviscid smoke
// (ch. 3.2, eq. 3.1) drops; a lid-driven cavity needs it. Each face component diffuses on its own
// face grid with the 2D+1-point Laplacian:
//   explicit:  u^{n+1} = u* + nu dt lap u*             (stable for nu dt / dx^2 <= 1 / (2 D))
//   implicit:  (I - nu dt lap) u^{n+1} = u*             (backward Euler, any dt; Jacobi-PCG)
// Faces with face weight 0 (domain walls, inside obstacles) keep their values and act as Dirichlet
// data for their neighbours. Across a domain wall parallel to a component the ghost value mirrors
// the wall: no-slip ghosts u_g = 2 U_wall - u (U_wall: the wall's tangential velocity, e.g. the
// cavity lid), free-slip ghosts u_g = u (zero shear). Open sides take zero gradient.
#include <array>
#include <vector>

#include "msim/core/domain_split.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/pressure/projection.hpp"

namespace msim::fluid {

enum class ViscosityMode { Explicit, Implicit };
enum class WallSlip { NoSlip, FreeSlip };

// Velocity of each domain wall [axis][0 = lower, 1 = upper] [m/s].
template <int D>
using WallVelocities = std::array<std::array<Vec<D>, 2>, D>;

template <int D>
WallVelocities<D> zeroWallVelocities() {
  WallVelocities<D> w;
  for (auto& s : w) s = {Vec<D>::Zero(), Vec<D>::Zero()};
  return w;
}

template <int D>
struct ViscosityBoundaries {
  numerics::DomainSides<D> sides;
  WallSlip slip = WallSlip::NoSlip;
  // Only the tangential part enters (no-slip ghosts).
  WallVelocities<D> wallVelocity = zeroWallVelocities<D>();
};

struct ViscositySolveSettings {
  double tolerance = 1e-6;  // relative max-norm residual of the implicit solve
  int maxIterations = 200;
};

template <int D>
class ViscousDiffusion {
 public:
  explicit ViscousDiffusion(const GridSpec<D>& spec);

  // Diffuses `velocity` by kinematic viscosity nu [m^2/s] over dt. `faceWeights` marks fixed faces
  // (weight 0), as PressureProjection::faceWeights() does. Returns the largest number of PCG
  // iterations over the components (0 for explicit).
  // Split among processes (`split`, Selle ch. 8.1's CG with exchanged rows and reduced dot
  // products): the velocity is a block with ghost layers; each rank updates its own faces, fills
  // the search direction's ghosts before every product and reduces the sums and norms, so the
  // iteration is the serial one up to the order of the sums. The ghosts are filled on return.
  int apply(MacGrid<D>& velocity, const MacGrid<D>& faceWeights, const ViscosityBoundaries<D>& boundaries,
            double nu, double dt, ViscosityMode mode, const ViscositySolveSettings& settings = {},
            DomainSplit<D>* split = nullptr);

 private:
  int solveComponent(int axis, Grid<float, D>& u, const Grid<float, D>& weight, const ViscosityBoundaries<D>& b,
                     double c, ViscosityMode mode, const ViscositySolveSettings& settings, DomainSplit<D>* split);

  GridSpec<D> spec_;
  std::vector<float> old_, r_, z_, p_, q_;  // sized to the largest face component
  std::array<Grid<float, D>, D> directions_;  // split runs: p per component, with ghosts
};

}  // namespace msim::fluid
