#pragma once
// Gases as density and temperature carried by a prescribed motion field (Stam ch. 6.3-6.4):
//   d(rho)/dt + u.grad(rho) = kappa_rho lap(rho) - alpha_rho rho + S_rho          (ch. 6.4.1)
//   dT/dt + u.grad(T)       = kappa_T lap(T) - alpha_T (T - T_ambient) + S_T
// Stam solves these with Lagrangian blobs (ch. 4.3.2); this is the grid solution the issue asks
// for first. The blobs carry mass, so density moves in flux (mass-conserving) form; temperature is
// the blobs' mass-weighted temperature (T = rho^-1 sum m_k T_k W), so it moves in advective form and
// a source mixes its gas in by mass. The radiative T^4 loss of flames belongs to fire (ch. 6.4.2);
// here L_T is the linear cooling towards ambient that Stam's non-reactive blobs use.
#include <cstddef>
#include <utility>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/timer.hpp"
#include "msim/fluid/gas/motion_field.hpp"
#include "msim/numerics/flux_transport.hpp"
#include "msim/turbulence/turbulent_wind.hpp"

namespace msim::fluid {

struct GasParams {
  double densityDiffusion = 0.0;     // kappa_rho [m^2/s]
  double densityDissipation = 0.0;   // alpha_rho [1/s]
  double ambientTemperature = 293.15;  // [K]
  double temperatureDiffusion = 0.0;   // kappa_T [m^2/s]
  double cooling = 0.0;                // alpha_T [1/s]
  double cfl = 0.9;                    // fraction of the stable step actually taken
};

// A source covers cells with weights in (0, 1] (the fraction of each cell inside its shape).
struct GasSource {
  std::vector<std::pair<std::size_t, float>> cells;  // (cell index, coverage)
  double densityRate = 0.0;  // S_rho [kg/(m^3 s)] in a fully covered cell
  double temperature = 0.0;  // [K] of the emitted gas
};

struct GasStatistics {
  double mass = 0.0;         // integral of rho [kg]
  double maxDensity = 0.0;   // [kg/m^3]
  double maxTemperature = 0.0;
  double meanTemperature = 0.0;  // mass-weighted [K]
  Vec3 centroid = Vec3::Zero();  // centre of mass [m] (z = 0 in 2D)
  bool finite = true;
};

template <int D>
class GasSolver {
 public:
  GasSolver(const GridSpec<D>& spec, const GasParams& params, const MotionField& field,
            const numerics::TransportBoundaries<D>& boundaries);

  // Cells with solid > 0.5 are obstacles: no gas, no flux through their faces.
  void setSolid(const Grid<float, D>& solid);
  void addSource(GasSource source) { sources_.push_back(std::move(source)); }
  // A turbulent wind added to the motion field (eq. 6.1: the plain sum, which the seed found to
  // work well): the face velocities become steady field + winds at the current time, resampled
  // after every step.
  void addWind(turbulence::TurbulentWind<D> wind);
  // Sets the clock the winds are sampled at (a resumed run) [s].
  void setTime(double time);
  double time() const { return time_; }
  const std::vector<turbulence::TurbulentWind<D>>& winds() const { return winds_; }

  // Largest step the explicit transport takes stably, times params.cfl [s].
  double stableTimestep() const;
  void step(double dt);

  GasStatistics statistics() const;
  // Wall time per stage of step() (emit, transport, decay, winds), for the run's stage table.
  const StageTimers& timers() const { return timers_; }
  void resetTimers() { timers_.reset(); }

  Grid<float, D>& density() { return density_; }
  const Grid<float, D>& density() const { return density_; }
  Grid<float, D>& temperature() { return temperature_; }
  const Grid<float, D>& temperature() const { return temperature_; }
  const MacGrid<D>& velocity() const { return transport_.velocity(); }
  const Grid<float, D>& solid() const { return transport_.solid(); }
  const GridSpec<D>& spec() const { return spec_; }
  const GasParams& params() const { return params_; }

 private:
  void emit(double dt);
  void decay(double dt);
  void refreshVelocity();

  GridSpec<D> spec_;
  GasParams params_;
  Grid<float, D> density_;
  Grid<float, D> temperature_;
  numerics::FluxTransport<D> transport_;
  std::vector<GasSource> sources_;
  MacGrid<D> steadyVelocity_;  // the motion field on the faces
  MacGrid<D> windyVelocity_;   // steady field + winds at the current time (scratch)
  std::vector<turbulence::TurbulentWind<D>> winds_;
  double time_ = 0.0;
  StageTimers timers_;
};

}  // namespace msim::fluid
