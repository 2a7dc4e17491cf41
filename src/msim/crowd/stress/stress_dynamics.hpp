#pragma once
// The motion of a crowd under inter-personal stress (Golas ch. 4.3-4.4, Fig. 4.1): each agent
// relaxes towards its collision-free velocity over tau and is pushed by the stress, discomfort
// (isotropic) and friction (trace-free),
//   a = (v_cf - v) / tau - (grad p + div s) / rho   (eq. 4.6),   |a| <= a_max   (eq. 4.7),
// integrated by the second-order midpoint method, the grid fields (stress_grid.hpp) evaluated
// at the step's start and at its midpoint, FLIP-style: the grid's accelerations are interpolated
// to the agents. Friction is solved on the momenta the other terms leave after the step,
// m* = rho (v + dt ((v_cf - v) / tau - grad p / rho)) (the seed's "v_t - grad p" of eq. 4.12),
// and acts as dt D s* / rho. The collision-free velocities are held over the step [the seed does
// not say whether its navigation is asked again at the midpoint].
#include <span>
#include <vector>

#include "msim/core/mac_grid.hpp"
#include "msim/crowd/stress/stress_grid.hpp"

namespace msim::crowd::stress {

struct StressSettings {
  StressLaws laws;
  double relaxation = 0.2;       // tau [s] (not given in the seed; docs/crowd_turbulence.md)
  double maxAcceleration = 3.0;  // a_max [m/s^2] (not given; people's 2-5)
  numerics::BoundQpSettings qp = [] {
    numerics::BoundQpSettings s;
    s.tolerance = 1e-4;  // the projected gradient against its start (the seed notes' suggestion)
    s.maxIterations = 200;
    return s;
  }();
};

struct StressStepStats {
  int solves = 0, iterations = 0, unconverged = 0;  // of the friction QP
  double dissipated = 0.0;                          // E(0) - E(s*) summed over the solves [kg/s^2 per m^2 ...]
};

class StressDynamics {
 public:
  StressDynamics(const GridSpec<2>& grid, const StressSettings& settings);
  const StressSettings& settings() const { return settings_; }

  // One midpoint step of length dt for the agents at x with velocities v towards `collisionFree`
  // (one each), the cells' free fractions `free`. Updates x and v.
  StressStepStats step(std::span<Vec2f> x, std::span<Vec2f> v, std::span<const Vec2f> collisionFree,
                       const Grid<float, 2>& free, double dt);
  // The fields of the last evaluation (the step's midpoint): density, velocities, stress.
  const StressGrid& fields() const { return grid_; }

 private:
  void accelerate(std::span<const Vec2f> x, std::span<const Vec2f> v, std::span<const Vec2f> collisionFree,
                  const Grid<float, 2>& free, double dt, StressStepStats& stats);

  StressSettings settings_;
  StressGrid grid_;
  MacGrid<2> discomfortGradient_, friction_;
  Eigen::VectorXd momentum_, change_;
  std::vector<Vec2f> acceleration_, halfX_, halfV_;
};

}  // namespace msim::crowd::stress
