#pragma once
// The internal stress of a granular continuum, Narain (2011) ch. 5.3 and 5.5: unilateral pressure
// (no tension, eqs. 5.10-5.13 in the multi-material form 5.47-5.48), frictional stress by maximal
// dissipation under the linearised Drucker-Prager bounds |s_ij| <= alpha p (eqs. 5.15-5.20,
// 5.49-5.50), solved one component at a time (ch. 5.5.1, eqs. 5.44-5.46) in staggered
// projections (ch. 5.3.5, two outer iterations by default), warm-started from the last step; the
// density correction of eq. 5.14; and the two-way coupling with rigid bodies of ch. 5.3.4
// (eqs. 5.21-5.27). Every quadratic program is a grid Poisson operator on its component's lattice
// (stress_lattice.hpp) plus, with bodies, a rank-6 term per body, solved by MPRGP (numerics/
// bound_qp) with Jacobi preconditioning.
#include <array>
#include <memory>
#include <vector>

#include "msim/granular/grid_state.hpp"
#include "msim/granular/stress_problem.hpp"

namespace msim::granular {

struct StressSolverSettings {
  int staggeredIterations = 2;  // outer p / s iterations (ch. 5.5: 2 in all the seed's results)
  bool friction = true;
  int upAxis = 1;               // its diagonal component is solved first (ch. 5.5.1 order)
  double tolerance = 1e-5;      // MPRGP relative projected-gradient tolerance
  double velocityTolerance = 3e-4;  // [m/s] friction solves stop once their velocity error is below
  int maxIterations = 400;      // per QP solve
  // Faces filled below this fraction respond to stress like a face filled this much: the
  // velocity change dt F / rho of eq. 5.5 grows without bound as a face's density goes to zero,
  // and the few grains that reach a free surface's faces would be shot off it by the pressure
  // holding the cells below. 0 gives eq. 5.5 unchanged.
  double minimumFaceFraction = 0.25;
  // Bit w set: the domain walls normal to axis w have no friction (the material slides along
  // them freely), e.g. the side walls of a quasi-2D slab. Walls are frictional by default.
  unsigned slipWalls = 0;
  // Bilateral incompressibility: cells at least half full also resist expansion (p may be
  // negative there, holding div(phi v) = 0), which makes a frictionless material an inviscid
  // liquid (FLIP with a particle free surface). Off: the unilateral constraint of eq. 5.10, under
  // which material dilates freely, as grains do. Not in the seed: for comparing sand with a liquid.
  bool bilateral = false;
};

// Time spent and work done in the last step (for the performance split of Table 5.1).
struct StressSolverStats {
  double pressureSeconds = 0.0, frictionSeconds = 0.0, correctionSeconds = 0.0;
  int pressureIterations = 0, frictionIterations = 0, correctionIterations = 0;
  int activePressureCells = 0;  // p > 0
};

class StressSolver {
 public:
  explicit StressSolver(StressSolverSettings settings = {});

  // Density correction (eq. 5.14): the displacement dx (on faces, zero on walls) that moves
  // material out of cells with phi + phi_s > 1, found by the pressure solve with dt = 1 and no
  // velocity; `phi` is updated in place (phi -= div(phi dx)). Returns the displacement.
  const FaceField& correctDensity(GranularGridState& state, const std::vector<const CoupledBody*>& bodies);

  // One step: from the predicted face velocity (v^n + dt f_ext / rho on open faces) to v~ of eq.
  // 5.27 with pressure and friction, in place. Bodies' velocities are not changed; bodyImpulse()
  // gives dt F of eq. 5.23 (without F_ext) for each.
  void solve(const GranularGridState& state, double dt, FaceField& velocity,
             const std::vector<const CoupledBody*>& bodies);

  // dt (-J1 p + J2 s) for body k of the last solve (eq. 5.23), in N s and N m s.
  const std::vector<Eigen::Matrix<double, 6, 1>>& bodyImpulses() const { return impulses_; }

  const std::vector<double>& pressure() const { return p_; }
  // Component c of the frictional stress (lattice of c), after the last solve.
  const std::vector<double>& stress(const StressComponent& c) const;
  const StressSolverStats& stats() const { return stats_; }
  StressSolverSettings& settings() { return settings_; }

 private:
  struct Impl;
  static void faceCoefficients(const GranularGridState& st, const std::vector<const CoupledBody*>& bodies,
                               double minimumFaceFraction, Impl& m);
  std::shared_ptr<Impl> impl_;
  StressSolverSettings settings_;
  StressSolverStats stats_;
  std::vector<double> p_;
  std::array<std::vector<double>, 6> s_;  // xx, yy, zz, xy, xz, yz
  // Where each component of s_ may be nonzero (empty: nowhere), so the friction's bookkeeping can
  // skip the rest of the grid.
  std::array<LatticeBox, 6> sBox_;
  std::vector<Eigen::Matrix<double, 6, 1>> impulses_;
  FaceField displacement_;
};

}  // namespace msim::granular
