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
  int apply(MacGrid<D>& velocity, const MacGrid<D>& faceWeights, const ViscosityBoundaries<D>& boundaries,
            double nu, double dt, ViscosityMode mode, const ViscositySolveSettings& settings = {});

 private:
  int solveComponent(int axis, Grid<float, D>& u, const Grid<float, D>& weight, const ViscosityBoundaries<D>& b,
                     double c, ViscosityMode mode, const ViscositySolveSettings& settings);

  GridSpec<D> spec_;
  std::vector<float> old_, r_, z_, p_, q_;  // sized to the largest face component
};

}  // namespace msim::fluid
