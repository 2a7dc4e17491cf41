#pragma once
// SmokeSolver<D>: incompressible smoke on a MAC grid, Selle ch. 3.2. The flow obeys
//   u_t + (u.grad) u + grad p / rho = f + nu lap u,   div u = 0           (eqs. 3.1, 3.2)
// with f the buoyancy of Fedkiw, Stam and Jensen and the vorticity confinement force built on
// omega = curl u (eq. 3.3). One step of size dt splits the operators as Selle does:
//   1. sources: set/add density and temperature in covered cells
//   2. advect u in itself (Advector: semi-Lagrangian, BFECC or MacCormack)   -> u*
//   3. forces: buoyancy, vorticity confinement (epsilon), then viscosity (optional, nu)
//   4. impose source inflow velocities, project: solve lap p = (rho/dt) div u*, u = u* - dt/rho grad p
//   5. advect density, temperature and extra scalars in the divergence-free u (with the Advector,
//      or conservatively with numerics::FluxTransport, see ScalarTransport), then dissipate
// Obstacles are static solids given by a signed distance (face fractions in the projection, cell
// mask for advection and forces) that may carry a velocity (moving-obstacle boundary condition).
// Storage is float, reductions double; every work array lives in the object (no allocation per
// step).
#include <array>
#include <cstddef>
#include <memory>
#include <optional>
#include <string>
#include <utility>
#include <vector>

#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/timer.hpp"
#include "msim/fluid/smoke/buoyancy.hpp"
#include "msim/fluid/smoke/viscosity.hpp"
#include "msim/fluid/smoke/vorticity_confinement.hpp"
#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/numerics/flux_transport.hpp"
#include "msim/numerics/pressure/projection.hpp"
#include "msim/numerics/solid_extension.hpp"
#include "msim/turbulence/turbulent_wind.hpp"

namespace msim::fluid {

// How step 5 moves density, temperature and the extra scalars.
enum class ScalarTransport {
  Advector,      // the velocity's scheme (params.advection): sharpest, not conservative
  Conservative   // finite-volume flux form (numerics::FluxTransport): conserves the total to round-off
};

template <int D>
struct SmokeParams {
  numerics::AdvectionSettings advection;     // scheme for velocity (and scalars with Advector)
  ScalarTransport scalarTransport = ScalarTransport::Advector;
  numerics::ProjectionSettings projection;   // MG-PCG by default
  numerics::DomainSides<D> sides;            // walls by default
  double fluidDensity = 1.0;                 // rho in the pressure equation [kg/m^3]
  BuoyancyParams buoyancy;                   // alpha = beta = 0: no buoyancy
  double vorticityEpsilon = 0.0;             // confinement strength (0: off)
  // Rate at which the air is pulled towards the turbulent winds (addWind) [1/s]: a drag force
  // c (u_wind - u) per unit mass, integrated exactly over the step.
  double windCoupling = 1.0;
  double viscosity = 0.0;                    // kinematic nu [m^2/s] (0: inviscid, as Selle)
  ViscosityMode viscosityMode = ViscosityMode::Implicit;
  ViscositySolveSettings viscositySolve;
  WallSlip wallSlip = WallSlip::NoSlip;      // tangential wall condition of the viscous term
  // Velocity of each wall: tangential parts drag (a cavity lid, viscous term), normal parts make
  // inflow and outflow walls (the projection's Neumann condition).
  WallVelocities<D> wallVelocity = zeroWallVelocities<D>();
  double densityDissipation = 0.0;           // rho *= exp(-rate dt) [1/s]
  double temperatureDissipation = 0.0;       // T - T_ambient *= exp(-rate dt) [1/s]
  double cfl = 1.0;                          // cells a face velocity may cross per substep
  int maxSubsteps = 16;                      // advance() never takes more
  bool checkFinite = true;                   // throw SimulationError on NaN/inf after each step
};

// Cells with coverage in (0, 1]. Density and temperature are blended towards the source values
// (set) or increased at a rate (add); the faces of covered cells get the inflow velocity, blended
// by coverage, just before the projection.
template <int D>
struct SmokeSource {
  std::vector<std::pair<std::size_t, float>> cells;  // (cell index, coverage)
  enum class Mode { Set, Add } mode = Mode::Set;
  double density = 0.0;      // Set: value [kg/m^3]; Add: rate [kg/(m^3 s)]
  double temperature = 0.0;  // Set: value [K]; Add: rate [K/s]; ignored when <= 0 in Set mode
  std::optional<Vec<D>> velocity;  // inflow [m/s]
  // Divergence [1/s] the projection leaves in covered cells, times their coverage: the gas an
  // explosion or a flame releases pushes the air out (Selle Fig. 3.4's divergence-driven
  // expansion). Where no side is open the box cannot grow, and the rest of the air is compressed
  // uniformly to make room (the projection removes the target's mean there).
  double expansion = 0.0;
  // Extra scalars (addScalar index, value or rate as for density), e.g. fuel for fire.
  std::vector<std::pair<std::size_t, double>> scalars;
  bool active = true;  // an inactive source does nothing (emitters switched on and off in time)
};

// A source's scalars over dt: Set blends density (and temperature, if > 0, and each extra scalar)
// towards its value by the coverage, Add adds coverage x rate x dt. scalar(i) returns the field of
// extra scalar i. Inactive sources do nothing.
template <int D, typename ScalarField>
void applySourceScalars(const SmokeSource<D>& src, double dt, Grid<float, D>& density, Grid<float, D>& temperature,
                        ScalarField&& scalar) {
  if (!src.active) return;
  const bool set = src.mode == SmokeSource<D>::Mode::Set;
  for (const auto& [cell, w] : src.cells) {
    if (set) {
      density[cell] += static_cast<float>(w * (src.density - density[cell]));
      if (src.temperature > 0.0) temperature[cell] += static_cast<float>(w * (src.temperature - temperature[cell]));
      for (const auto& [index, value] : src.scalars) {
        float& v = scalar(index)[cell];
        v += static_cast<float>(w * (value - v));
      }
    } else {
      density[cell] += static_cast<float>(w * src.density * dt);
      temperature[cell] += static_cast<float>(w * src.temperature * dt);
      for (const auto& [index, rate] : src.scalars) scalar(index)[cell] += static_cast<float>(w * rate * dt);
    }
  }
}

struct SmokeStatistics {
  double kineticEnergy = 0.0;   // 1/2 rho sum_faces w_f u_f^2 dV [J per unit depth in 2D]
  double maxDivergence = 0.0;   // max |div u - expansion| after the last projection [1/s]
  double totalDensity = 0.0;    // integral of density over the cells that carry scalars [kg]
                                // (Advector: centre outside obstacles; Conservative: any open face)
  double maxSpeed = 0.0;        // max |u_f| over faces [m/s]
  int pressureIterations = 0;   // last projection
  int viscosityIterations = 0;  // last implicit viscosity solve
  long step = 0;                // steps taken
  double enstrophy = 0.0;       // 1/2 sum_cells |curl u|^2 dV [m^3/s^2 (m^2/s^2 per unit depth in 2D)]
  std::size_t vortexParticles = 0;
};

// The measures of a smoke state that SmokeSolver::statistics() reports, from its fields, into
// `out`: kinetic energy (faces weighted by `weights`; all open when null), fastest face, smoke
// mass outside the `excluded` cells (all cells when null) and enstrophy. A run split among
// processes measures the fields gathered on rank 0 with it.
template <int D>
void measureSmoke(const MacGrid<D>& velocity, const MacGrid<D>* weights, const Grid<float, D>& density,
                  const Grid<float, D>* excluded, double fluidDensity, SmokeStatistics& out);

// Smoke decays as exp(-densityRate dt) per step and T - T_ambient as exp(-temperatureRate dt)
// (params.densityDissipation, temperatureDissipation), on whichever grid carries them.
template <int D>
void dissipateSmoke(Grid<float, D>& density, Grid<float, D>& temperature, double densityRate, double temperatureRate,
                    double ambientTemperature, double dt);

template <int D>
class SmokeSolver {
 public:
  SmokeSolver(const GridSpec<D>& spec, const SmokeParams<D>& params);
  SmokeSolver(const SmokeSolver&) = delete;
  SmokeSolver& operator=(const SmokeSolver&) = delete;

  // Static obstacle from a signed distance sampled at the grid nodes (res+1 per axis, negative
  // inside; numerics::sampleNodes). Cells whose centre lies inside are solid for advection/forces;
  // the conservative transport excludes only cells without an open face. May be called again
  // (moving obstacles): every mask and the projection are rebuilt.
  void setObstacles(const Grid<float, D>& nodalSolidPhi);
  // Velocity of the obstacles on each face [m/s] (moving-obstacle boundary condition).
  void setObstacleVelocity(const MacGrid<D>& solidVelocity);
  void addSource(SmokeSource<D> source) { sources_.push_back(std::move(source)); }
  // A turbulent wind acting on the air as a force (params.windCoupling); several add up.
  void addWind(turbulence::TurbulentWind<D> wind) { winds_.push_back(std::move(wind)); }
  // Bound on the winds' summed speed [m/s] (0 without winds), for the time step.
  double maxWindSpeed() const;
  // Velocity added to U when U advects itself (procedural turbulence's coupling, Narain ch. 3.5.2:
  // U moves with U + u'); null: U alone. The grid must outlive its use.
  void setAdvectionOffset(const MacGrid<D>* offset) { advectionOffset_ = offset; }
  // Procedural turbulence carries density and temperature on its own finer grid and sets the
  // solver's each step (their averages): the solver then neither advects nor dissipates them.
  void setScalarsCarriedElsewhere(bool elsewhere) { scalarsElsewhere_ = elsewhere; }
  // Vortex particles (Selle ch. 3.3-3.5, fluid/vortex): their force joins the body forces and they
  // move after the projection. Set before setObstacles, which hands them the obstacles; the
  // initial particles are seeded here.
  void setVortexLayer(std::unique_ptr<VortexLayer<D>> layer);
  const VortexLayer<D>* vortexLayer() const { return vortex_.get(); }
  VortexLayer<D>* vortexLayer() { return vortex_.get(); }
  // Runs the solver on one block of a grid split among processes (msim/parallel): the solver's
  // spec is the block's local grid, ghosts are exchanged where stencils read them, scalars are
  // reduced over the ranks and the pressure solve is the split's (with the static obstacles).
  // Moving obstacles, vortex particles, viscosity, conservative scalar transport, expanding
  // sources, moving walls and procedural turbulence are not distributed: step() throws
  // InputError naming the one in use. `split` must outlive the solver.
  void setDomainSplit(DomainSplit<D>* split);
  // The clock the winds are sampled at [s]; step() advances it, a resumed run sets it.
  void setTime(double time) { time_ = time; }
  double time() const { return time_; }
  const std::vector<turbulence::TurbulentWind<D>>& winds() const { return winds_; }
  SmokeSource<D>& source(std::size_t i) { return sources_[i]; }
  std::size_t sourceCount() const { return sources_.size(); }
  // A further advected cell-centred scalar (e.g. fuel), dissipating as rho does; returns its index.
  std::size_t addScalar(std::string name, double dissipation = 0.0, float initial = 0.0f);

  // Largest step with max face speed * dt <= cfl * dx (infinite when the fluid is at rest), and
  // within the stability limit of explicit viscosity when that is on.
  double cflTimestep() const;
  // One step of size dt (steps 1-5 above).
  void step(double dt);
  // Advances by dt in ceil(dt / cflTimestep()) equal substeps, at most params.maxSubsteps;
  // returns the number of substeps.
  int advance(double dt);

  SmokeStatistics statistics() const;
  // The solver's own counts (the last solves, steps, vortex particles) without the measures of
  // its fields (measureSmoke): a split run measures the fields gathered on rank 0 instead.
  SmokeStatistics counters() const;

  MacGrid<D>& velocity() { return velocity_; }
  const MacGrid<D>& velocity() const { return velocity_; }
  Grid<float, D>& density() { return density_; }
  const Grid<float, D>& density() const { return density_; }
  Grid<float, D>& temperature() { return temperature_; }
  const Grid<float, D>& temperature() const { return temperature_; }
  Grid<float, D>& scalar(std::size_t i) { return scalars_[i].field; }
  const Grid<float, D>& scalar(std::size_t i) const { return scalars_[i].field; }
  const std::string& scalarName(std::size_t i) const { return scalars_[i].name; }
  std::size_t scalarCount() const { return scalars_.size(); }
  const Grid<float, D>& solid() const { return solid_; }
  const numerics::PressureProjection<D>& projection() const { return projection_; }
  // The last pressure [Pa]; it warm-starts the next projection, so a resumed run restores it.
  Grid<float, D>& pressure() { return projection_.pressure(); }
  const Grid<float, D>& pressure() const { return projection_.pressure(); }
  const GridSpec<D>& spec() const { return spec_; }
  const SmokeParams<D>& params() const { return params_; }
  SmokeParams<D>& params() { return params_; }
  // Wall time per stage (sources, advect velocity, forces, viscosity, project, vortex particles,
  // advect scalars).
  const StageTimers& timers() const { return timers_; }
  void resetTimers() { timers_.reset(); }

 private:
  struct Scalar {
    std::string name;
    double dissipation;
    Grid<float, D> field;
  };
  // The FluxTransport and its carrying face velocities, built by the first Conservative step.
  struct Conservative {
    numerics::FluxTransport<D> transport;
    MacGrid<D> faceVelocity;  // w_f u_f: the fluid volume flux per unit face area
  };
  void resetInflowCells();
  void applyScalarSources(double dt);
  void advectScalars(double dt);
  void transportScalarsConservatively(double dt);
  void updateSealed();
  void findCutFaces();
  void extrapolateIntoCutFaces();
  void applyInflow();
  // Fills expansion_ from the active expanding sources and hands it to the projection.
  void updateExpansion();
  void dissipate(double dt);
  void applyWinds(double dt);
  void checkFinite() const;
  // Split runs: throws InputError if a feature that is not distributed is in use.
  void checkDistributable() const;
  // max |div u - expansion| after the projection (split runs: over the owned cells of every
  // rank, velocity ghosts filled).
  double measureDivergence();

  GridSpec<D> spec_;
  SmokeParams<D> params_;
  MacGrid<D> velocity_;
  Grid<float, D> density_, temperature_, solid_, divergence_;
  Grid<float, D> expansion_;  // the sources' target divergence [1/s]; empty while none expands
  // Cells with no open face (projection weight 0 on all 2D faces): no pressure, no flux; the
  // conservative transport's solid mask.
  Grid<float, D> sealed_;
  std::vector<Scalar> scalars_;
  std::vector<SmokeSource<D>> sources_;
  bool hasObstacles_ = false;
  // The solid cells next to the fluid: the scalars are extended into them before advection so
  // back-traces that end inside an obstacle read fluid values.
  numerics::SolidExtension<D> border_;
  // Per velocity component: faces open in the projection (weight > 0) that the advector keeps
  // fixed because they border a solid cell, with their advected same-component neighbours (CSR).
  struct CutFaces {
    std::vector<std::size_t> faces, start, neighbours;
  };
  std::array<CutFaces, D> cutFaces_;
  numerics::Advector<float, D> advector_;
  std::unique_ptr<Conservative> conservative_;
  numerics::PressureProjection<D> projection_;
  VorticityConfinement<D> confinement_;
  ViscousDiffusion<D> viscosity_;
  StageTimers timers_;
  DomainSplit<D>* split_ = nullptr;
  double maxDivergence_ = 0.0;
  int pressureIterations_ = 0, viscosityIterations_ = 0;
  long steps_ = 0;
  std::vector<turbulence::TurbulentWind<D>> winds_;
  std::vector<float> windScratch_;  // the winds on one face component
  const MacGrid<D>* advectionOffset_ = nullptr;
  bool scalarsElsewhere_ = false;
  std::optional<MacGrid<D>> advecting_;  // U + offset
  double time_ = 0.0;
  std::unique_ptr<VortexLayer<D>> vortex_;
};

}  // namespace msim::fluid
