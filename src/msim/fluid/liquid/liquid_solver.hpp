#pragma once
// LiquidSolver<D>: water with a free surface on a MAC grid (Selle ch. 4.4.3, Enright, Marschner &
// Fedkiw 2002). phi < 0 is liquid. One step of size dt:
//   1. the surface moves: phi is advected (the velocity's scheme) and corrected by the particle
//      level set's escaped particles, reinitialised by fast marching, corrected again; the
//      particles' radii follow phi, and every reseedInterval steps the band is reseeded;
//   2. the velocity advects itself (it has been extended across the surface, so the back-traces
//      that leave the liquid read sensible values);
//   3. gravity;
//   4. pressure with the free surface (ghost fluid, p = 0 at the surface) and the solids' face
//      fractions; the liquid cells only carry unknowns;
//   5. the velocity is extended from the faces next to the liquid along the normals, in increasing
//      phi, over the band (Selle ch. 4.4.3); faces beyond it are set to 0 and closed faces take
//      the solid's velocity.
// With FLIP particles (params.tracker) steps 1-2 become: the particles move through the grid
// velocity, phi is rebuilt from them and reinitialised, their velocities are splatted onto the
// faces and extended; after step 5 the particles take the change of the grid velocity (FLIP)
// blended with the new velocity itself (PIC) by params.flipRatio (Golas ch. 2.7).
// Volume control (params.volumeControl; Kim, Liu, Llamas, Jiao & Rossignac 2007): both trackers
// lose volume where sheets and spray thin below a cell, and FLIP's rebuilt surface breathes as
// its particles bunch. Step 4 then asks the liquid cells for the divergence
// c = -(k_p x + k_i int x dt) / (x + 1), x = V / V_target - 1: with dV/dt = c V this makes
// dx/dt = -k_p x - k_i int x dt, a PI controller that drives the relative error back to 0. The
// rate at which the surface lost volume in the last step beyond what the control asked for is fed
// forward (a splash that hits a wall loses several percent within a few steps, faster than the PI
// gains follow). The target is the starting volume plus what emitters added and came in through
// open sides less what sinks and open sides took (FLIP: the particles' volume, scaled as the
// surface first measured it). The correction is spread over the whole liquid, not put back where
// the volume was lost.
// Vortex particles (setVortexLayer; Selle ch. 3.3-3.5, fluid/vortex) add their force with gravity
// in step 3 and move with the velocity after step 5; those that leave the liquid are deleted (the
// air carries no vorticity: Fig. 3.3's river eddies live in the water).
// Split among processes (setDomainSplit; Selle ch. 8.1) the solver runs on one block of the grid
// with ghost layers: phi and the velocity are exchanged before the stencils that read the
// neighbours' cells, each marker particle lives on the process whose cells hold it (migrated after
// every move, the neighbours' copies near the block read by the correction), the fast marching
// and the velocity extension run on the block with its ghosts, the volume and the statistics are
// summed over the processes and the pressure is solved by the split (hypre).
// Obstacles are solids given by a signed distance at the grid nodes, as for smoke; moving ones are
// placed again before every step with the velocity of the solid on every face, which the pressure
// uses as the boundary condition (the solid pushes the liquid through its faces' closed parts). Storage
// is float, reductions double; the work arrays live in the object.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <optional>
#include <vector>

#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/timer.hpp"
#include "msim/fluid/liquid/flip_particles.hpp"
#include "msim/fluid/vortex/vortex_layer.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/numerics/level_set/particle_level_set.hpp"
#include "msim/numerics/pressure/projection.hpp"
#include "msim/numerics/solid_extension.hpp"

namespace msim::fluid {

template <int D>
Vec<D> standardGravity() {
  Vec<D> g = Vec<D>::Zero();
  g[1] = -9.81;
  return g;
}

// How the surface is tracked (issue #24): a particle level set, or FLIP particles that carry the
// liquid and its velocity (phi rebuilt from them every step).
enum class InterfaceTracker { ParticleLevelSet, Flip };

// The marker particles of a liquid: escaped ones are deleted at reseeding (see the setting).
inline numerics::ParticleLevelSetSettings liquidParticleSettings() {
  numerics::ParticleLevelSetSettings s;
  s.deleteEscapedOnReseed = true;
  return s;
}

template <int D>
struct LiquidParams {
  InterfaceTracker tracker = InterfaceTracker::ParticleLevelSet;
  Vec<D> gravity = standardGravity<D>();     // [m/s^2]
  double density = 1000.0;                   // rho of the liquid [kg/m^3]
  numerics::AdvectionSettings advection;     // velocity and phi
  numerics::ProjectionSettings projection;   // MG-PCG with the free surface
  numerics::DomainSides<D> sides;            // walls by default
  numerics::ParticleLevelSetSettings particleLevelSet = liquidParticleSettings();
  // Steps between reseedings of the particle level set (each also deletes the escaped particles):
  // in the 2D dam break (scenes/dam_break_2d.json) 5 keeps 93% of the water after 2.5 s, 20 87%.
  int reseedInterval = 5;
  double flipRatio = 0.95;                   // FLIP share of the PIC/FLIP blend (1: FLIP, 0: PIC)
  int flipParticlesPerCell = 0;              // 0: 2 per axis (4 in 2D, 8 in 3D)
  std::uint64_t seed = 1;                    // FLIP seeding
  double bandCells = 6.0;                    // phi is a distance within this many cells
  double extrapolationCells = 5.0;           // velocity extended this far beyond the surface
  double cfl = 1.0;                          // cells the fastest face may cross per substep
  bool volumeControl = true;                 // hold the volume (Kim et al. 2007; see above)
  // Steps in which a volume error decays. Kim et al. use 25 for slowly leaking bubbles; in the 3D
  // dam break of tests/fluid_liquid/volume_test.cpp at 48 x 30 x 18 cells the particle level set
  // strays by up to 2.4% with 25, 1.6% with 10, 1.05% with 5 and 1.07% with 4 (FLIP: 2.6% with 5,
  // 2.7% with 4).
  double volumeControlSteps = 5.0;
  int maxSubsteps = 64;                      // advance() refuses to take more (SimulationError)
};

struct LiquidStatistics {
  double volume = 0.0;          // liquid volume (smeared Heaviside of phi, outside solids) [m^3]
  double targetVolume = 0.0;    // what volume control holds the liquid to [m^3]
  double controlDivergence = 0.0;  // the divergence volume control asked for in the last step [1/s]
  double maxSpeed = 0.0;        // max |u_f| over faces with liquid on a side [m/s]
  double kineticEnergy = 0.0;   // 1/2 rho sum over liquid cells of |u|^2 dV [J] (per unit depth in 2D)
  int pressureIterations = 0;   // last projection
  bool pressureConverged = true;
  std::size_t particles = 0;    // marker particles
  std::size_t escaped = 0;      // escaped particles the last correction used
  double enstrophy = 0.0;       // 1/2 sum over liquid cells of |curl u|^2 dV [m^3/s^2 in 3D]
  std::size_t vortexParticles = 0;
  long step = 0;
};

// Volume control's state: what it holds the volume to [m^3], the PI controller's integral of the
// relative error [s] and its last error, its last output (a target divergence [1/s]), the leak
// estimate [1/s], FLIP's rebuilt-surface volume per particle volume (0: not measured yet), and
// whether it has measured yet.
struct VolumeControlState {
  double target = 0.0, errorIntegral = 0.0, lastError = 0.0, divergence = 0.0, leakRate = 0.0, flipScale = 0.0;
  bool started = false;
};

template <int D>
class LiquidSolver {
 public:
  LiquidSolver(const GridSpec<D>& spec, const LiquidParams<D>& params);
  LiquidSolver(const LiquidSolver&) = delete;
  LiquidSolver& operator=(const LiquidSolver&) = delete;

  // Obstacles from a signed distance at the grid nodes (numerics::sampleNodes), negative inside;
  // cells whose centre is inside are solid. Moving obstacles: call it before every step, with
  // setObstacleVelocity (the velocity of the solid on every face, 0 by default).
  void setObstacles(const Grid<float, D>& nodalSolidPhi);
  void setObstacleVelocity(const MacGrid<D>& solidVelocity) {
    projection_.setSolidVelocity(solidVelocity);
    if (split_) split_->setSolidVelocity(solidVelocity);
  }
  // Adds liquid where cellPhi < 0 (the union with what is there), moving at `velocity`. Before
  // the first step: the particles are seeded then.
  void addLiquid(const Grid<float, D>& cellPhi, const Vec<D>& velocity = Vec<D>::Zero());

  // An emitter (call between steps): liquid fills the cells where region < 0 (outside solids) and
  // the faces touching them move at `velocity`; with FLIP the particles there take the velocity
  // and the cells are topped up with new ones. Where the region lies against a closed side, the
  // side's faces there let the liquid in at `velocity` for the next step (an inflow). A sink: the liquid where region < 0 is removed.
  // Volume control's target follows both. Each returns the volume it added or removed [m^3].
  double emit(const Grid<float, D>& region, const Vec<D>& velocity);
  double drain(const Grid<float, D>& region);

  // A saved state (--resume): phi, the face velocities and the number of steps taken. Assign the
  // saved particles first (levelSetParticles() / flipParticles()); a particle level set left
  // empty is seeded afresh from phi. Volume control holds the restored volume from then on,
  // unless its saved state is restored after (restoreVolumeControl).
  void restore(const Grid<float, D>& phi, const MacGrid<D>& velocity, long steps);
  // Volume control's state; a resumed run that restores it after restore() holds the volume the
  // uninterrupted run holds, not the one its saved surface had.
  const VolumeControlState& volumeControl() const { return control_; }
  void restoreVolumeControl(const VolumeControlState& state) { control_ = state; }

  // Largest step with (max speed + sqrt(|g| dx)) dt <= cfl dx: the gravity term keeps a liquid at
  // rest from taking an unbounded first step.
  double cflTimestep() const;
  void step(double dt);
  // Advances by dt in ceil(dt / cflTimestep()) equal substeps; SimulationError (naming the step
  // and the speed) when that would exceed params.maxSubsteps. Returns the number of substeps.
  int advance(double dt);

  // Splits the liquid among processes (null: one process): the solver's grid is this process's
  // block (split->localSpec()). Call it before the obstacles, the liquid and the vortex particles
  // are added (std::invalid_argument after), and call emit and drain on every process alike.
  // Marker and FLIP particles live on the process owning their cell; vortex particles are kept
  // whole on every process (VortexLayer).
  void setDomainSplit(DomainSplit<D>* split);

  // Vortex particles in the liquid (null: none); the initial ones are seeded here, so call it
  // after the obstacles and the initial liquid are in place.
  void setVortexLayer(std::unique_ptr<VortexLayer<D>> layer);
  const VortexLayer<D>* vortexLayer() const { return vortex_.get(); }
  VortexLayer<D>* vortexLayer() { return vortex_.get(); }
  // The clock the vortex particles' seeding window is read at [s]; step() advances it, a resumed
  // run sets it.
  void setTime(double time) { time_ = time; }
  double time() const { return time_; }

  LiquidStatistics statistics() const;
  // The liquid's volume now [m^3] (a split run: over every process; collective).
  double liquidVolume() const;
  // The liquid's volume at the end of the last step [m^3] (measured once its surface had moved;
  // the rest of a step leaves phi as it is).
  double volume() const { return volume_; }
  const Grid<float, D>& phi() const { return phi_; }
  const MacGrid<D>& velocity() const { return velocity_; }
  MacGrid<D>& velocity() { return velocity_; }
  const Grid<float, D>& pressure() const { return projection_.pressure(); }
  const Grid<float, D>& solid() const { return solid_; }
  const numerics::ParticleLevelSet<D>& levelSetParticles() const { return particles_; }
  numerics::ParticleLevelSet<D>& levelSetParticles() { return particles_; }
  const FlipParticles<D>& flipParticles() const { return flip_; }
  FlipParticles<D>& flipParticles() { return flip_; }
  const GridSpec<D>& spec() const { return spec_; }
  const LiquidParams<D>& params() const { return params_; }
  const numerics::PcgStats& lastPressureSolve() const { return lastSolve_; }
  long steps() const { return steps_; }
  const StageTimers& timers() const { return timers_; }
  void resetTimers() { timers_.reset(); }

 private:
  void start();
  void moveSurface(double dt);
  void moveFlipSurface(double dt);
  void extendVelocity();
  // phi continued into the obstacles (intoSolids_), then fast marching.
  void reinitialize();
  // Liquid volume [m^3] that leaves through the domain's sides in dt at the current velocity: open
  // sides, and walls (negative: their faces that emitters let liquid in through).
  double boundaryOutflow(double dt) const;
  // An emitter against a wall: the wall's faces under it get its velocity (see emit).
  void markWallInflow(const Grid<float, D>& region, const Vec<D>& velocity);
  // Hands the pressure solve (and a split run's) this step's wall inflow, or clears last step's.
  void applyWallInflow();
  // Kim et al.'s divergence for the volume just measured after the surface moved (0 when off).
  double volumeControlDivergence(double dt);
  // Volume control starts afresh from the volume phi holds now.
  void resetVolumeControl();
  // Applies edit(cell index) to the particle level set's phi, drops its particles in `region` and
  // moves volume control's target by the volume change, which it returns [m^3].
  template <typename Edit>
  double editLevelSet(const Grid<float, D>& region, Edit&& edit);
  bool liquidCell(std::size_t cell) const { return phi_[cell] < 0.0f && solid_[cell] <= 0.5f; }
  // Whether the grid's side `side` (0 lower, 1 upper) along `axis` is the domain's (every side
  // without a split; a block's inner edges are not).
  bool onDomainSide(int axis, int side) const {
    if (placement_.whole()) return true;
    return side == 0 ? placement_.cellOrigin[axis] == 0
                     : placement_.cellOrigin[axis] + spec_.res[axis] == placement_.globalRes[axis];
  }
  // A split run: the marker particles that left this block go to their owners, and the
  // neighbours' particles near it are copied for the correction.
  void exchangeParticles();
  template <typename Tracked>
  void exchangeParticles(Tracked& particles, int reach);
  // The liquid volume of `particles` FLIP particles [m^3] (a split run: this process's, summed).
  double flipVolume(std::size_t particles) const;
  void moveSplitSurface(double dt);
  // A split run: every process stops together when one holds a non-finite value.
  void checkFiniteSplit() const;
  // The vortex particles' move (VortexLayer::advance), then those outside the liquid go.
  void advanceVortexParticles(double dt);
  void dropVortexParticlesInAir();
  // Whether face f of `axis` has a cell on either side for which isLiquid(cell index) holds.
  template <typename IsLiquid>
  bool faceTouches(int axis, const IVec<D>& f, IsLiquid&& isLiquid) const;

  GridSpec<D> spec_;
  LiquidParams<D> params_;
  DomainSplit<D>* split_ = nullptr;
  BlockPlacement<D> placement_;  // the block's place in the global grid (a split run)
  IndexBox<D> owned_;             // this process's own cells (local coordinates; all without a split)
  Grid<float, D> phi_;
  Grid<float, D> solid_;
  std::optional<Grid<float, D>> solidDistance_;  // the obstacles' nodal signed distance, if any
  numerics::SolidExtension<D> intoSolids_;          // phi's continuation into the obstacles
  MacGrid<D> velocity_;
  numerics::Advector<float, D> advector_;
  numerics::PressureProjection<D> projection_;
  numerics::ParticleLevelSet<D> particles_;
  FlipParticles<D> flip_;
  MacGrid<D> gridVelocityBefore_;                      // FLIP: the splatted velocity before forces
  Grid<float, D> pressurePhi_;                         // phi with the solids dry
  std::array<Grid<float, D>, D> facePhi_;              // phi at each face grid's samples
  std::array<std::vector<std::uint8_t>, D> known_;     // per face: value given (extension)
  numerics::PcgStats lastSolve_;
  std::size_t lastEscaped_ = 0;
  double volume_ = 0.0;
  VolumeControlState control_;
  bool started_ = false;
  long steps_ = 0;
  std::uint64_t emissions_ = 0;  // emit() calls so far (new random streams each)
  std::optional<MacGrid<D>> wallInflow_;  // emitters' wall faces (markWallInflow), this step
  bool inflowThisStep_ = false, inflowApplied_ = false;  // set by emit(); in the projection
  std::unique_ptr<VortexLayer<D>> vortex_;
  double time_ = 0.0;
  StageTimers timers_;
};

}  // namespace msim::fluid
