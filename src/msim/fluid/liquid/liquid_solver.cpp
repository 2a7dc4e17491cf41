#include "msim/fluid/liquid/liquid_solver.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"
#include "msim/core/resample.hpp"
#include "msim/numerics/level_set/extrapolation.hpp"
#include "msim/numerics/level_set/fast_marching.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"

namespace msim::fluid {

template <int D>
LiquidSolver<D>::LiquidSolver(const GridSpec<D>& spec, const LiquidParams<D>& params)
    : spec_(spec),
      params_(params),
      phi_(spec, static_cast<float>(params.bandCells * spec.dx)),
      solid_(spec, 0.0f),
      velocity_(spec),
      advector_(spec, params.advection),
      projection_(spec, params.sides, params.projection),
      particles_(spec, params.particleLevelSet),
      flip_(spec, params.flipParticlesPerCell, params.seed),
      pressurePhi_(spec) {
  if (!(params.density > 0.0) || !(params.cfl > 0.0) || params.maxSubsteps < 1 || params.reseedInterval < 1 ||
      !(params.bandCells >= 3.0) || !(params.extrapolationCells > 0.0) ||
      !(params.extrapolationCells < params.bandCells) || !(params.flipRatio >= 0.0 && params.flipRatio <= 1.0))
    throw std::invalid_argument("liquid solver: density, cfl, substeps and reseeding must be positive, the band at "
                                "least 3 cells and wider than the velocity extension, the FLIP ratio in [0, 1]");
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    facePhi_[a] = Grid<float, D>(spec, u.size(), u.offset());
    known_[a].assign(u.count(), 0);
  }
  owned_ = {IVec<D>::Zero(), spec.res};
}

template <int D>
void LiquidSolver<D>::setDomainSplit(DomainSplit<D>* split) {
  if (split && (vortex_ || steps_ > 0 || started_))
    throw std::invalid_argument("liquid solver: a split run is split before its vortex particles and its first step");
  split_ = split;
  placement_ = split ? split->placement() : BlockPlacement<D>{};
  owned_ = split ? split->owned() : IndexBox<D>{IVec<D>::Zero(), spec_.res};
  advector_.setPlacement(placement_);
  particles_.setBlock(placement_, owned_);
  flip_.setBlock(placement_, owned_);
}

template <int D>
void LiquidSolver<D>::setObstacles(const Grid<float, D>& nodalSolidPhi) {
  numerics::solidCellsFromNodes(nodalSolidPhi, solid_);
  // The faces of cells counted as solid (centre inside) are closed: the surface, the particles and
  // the volume all leave those cells out, so the pressure must not let the liquid flow into them
  // (through a curved wall's partly open faces it did, and FLIP water poured into a glass packed
  // into a film on its floor). Faces between open cells keep their fractions (Batty et al. 2007).
  MacGrid<D> open = numerics::openFaceFractions<D>(spec_, nodalSolidPhi);
  for (int a = 0; a < D; ++a) {
    auto& w = open.component(a);
    parallelForCells(w, [&](const IVec<D>& f, std::size_t lin) {
      if (faceTouches(a, f, [&](std::size_t cell) { return solid_[cell] > 0.5f; })) w[lin] = 0.0f;
    });
  }
  projection_.setSolids(open);
  if (split_) split_->setOpenFractions(projection_.faceWeights());
  solidDistance_ = nodalSolidPhi;
  if (vortex_) vortex_->setSolid(nodalSolidPhi);
  // phi continues three cells into the obstacles (a 90-degree contact, as the domain's clamped
  // sides give). Left with the air's sign, a wall would be a surface of the liquid, which the
  // level set then eroded along every obstacle (a pool in a box container lost half its water in a
  // second).
  intoSolids_ = numerics::SolidExtension<D>(solid_, 3);
  advector_.setSolid(solid_);
}

template <int D>
template <typename IsLiquid>
bool LiquidSolver<D>::faceTouches(int axis, const IVec<D>& f, IsLiquid&& isLiquid) const {
  IVec<D> low = f;
  low[axis] -= 1;
  return (f[axis] < spec_.res[axis] && isLiquid(phi_.index(f))) || (f[axis] > 0 && isLiquid(phi_.index(low)));
}

template <int D>
void LiquidSolver<D>::addLiquid(const Grid<float, D>& cellPhi, const Vec<D>& velocity) {
  if (!cellPhi.sameLayout(phi_)) throw std::invalid_argument("liquid solver: addLiquid needs a cell-centred phi");
  // The domain's sides are no surface of the liquid: a body that reaches a side (a pool filled to
  // the tank's walls) has a distance that kinks in the cells next to it, where the side is nearer
  // than the free surface. Those cells take the depth of their inner neighbour when it is deeper
  // (a zero normal derivative at the wall), or the surface would start tilted there; axis by axis,
  // each pass reading the last one's values, so cells along an edge or in a corner get it too.
  Grid<float, D> body = cellPhi;
  for (int a = 0; a < D; ++a) {
    const int cells = placement_.whole() ? spec_.res[a] : placement_.globalRes[a];  // along the whole domain
    if (cells < 3) continue;  // the inner neighbours must not be side cells themselves
    parallelForCells(body, [&](const IVec<D>& c, std::size_t i) {
      const int g = c[a] + placement_.cellOrigin[a];  // a split run's block: in the global grid
      if (g != 0 && g != cells - 1) return;
      IVec<D> inner = c;
      inner[a] += g == 0 ? 1 : -1;
      if (body[i] < 0.0f) body[i] = std::min(body[i], body(inner));
    });
  }
  for (std::size_t i = 0; i < phi_.count(); ++i) phi_[i] = std::min(phi_[i], body[i]);
  // Faces with new liquid on a side move with it.
  for (int a = 0; a < D; ++a) {
    auto& u = velocity_.component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (faceTouches(a, f, [&](std::size_t cell) { return cellPhi[cell] < 0.0f; }))
        u[lin] = static_cast<float>(velocity[a]);
    });
  }
  started_ = false;
}

template <int D>
double LiquidSolver<D>::emit(const Grid<float, D>& region, const Vec<D>& velocity) {
  if (!region.sameLayout(phi_)) throw std::invalid_argument("liquid solver: emit needs a cell-centred region");
  if (!started_) start();
  ScopedStage s(timers_, "liquid: sources");
  for (int a = 0; a < D; ++a) {
    auto& u = velocity_.component(a);
    const auto& w = projection_.faceWeights().component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (w[lin] > 0.0f && faceTouches(a, f, [&](std::size_t cell) { return region[cell] < 0.0f; }))
        u[lin] = static_cast<float>(velocity[a]);
    });
  }
  markWallInflow(region, velocity);
  if (params_.tracker == InterfaceTracker::Flip)  // the particles are the liquid (phi is rebuilt from them)
    return flipVolume(flip_.emit(region, solid_, velocity.template cast<float>(), ++emissions_));
  return editLevelSet(region, [&](std::size_t i) {
    if (solid_[i] <= 0.5f) phi_[i] = std::min(phi_[i], region[i]);
  });
}

template <int D>
void LiquidSolver<D>::markWallInflow(const Grid<float, D>& region, const Vec<D>& velocity) {
  // Where the region lies against a wall and its velocity points into the domain, the wall's faces
  // there let the liquid in: the pressure then pushes the liquid in front of the emitter on at its
  // velocity (a region already full of liquid would otherwise add nothing: the projection would
  // hold the liquid in it still against the closed wall). Cleared after the step.
  for (int a = 0; a < D; ++a)
    for (int side = 0; side < 2; ++side) {
      if (params_.sides.side[a][side] != numerics::DomainSide::Wall) continue;
      const double inward = side == 0 ? velocity[a] : -velocity[a];
      if (!(inward > 0.0)) continue;
      if (!wallInflow_) wallInflow_.emplace(spec_, 0.0f);
      auto& u = wallInflow_->component(a);
      if (!onDomainSide(a, side)) continue;  // a split run's block: its edge here lies inside the domain
      parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
        if (f[a] != (side == 0 ? 0 : spec_.res[a])) return;
        IVec<D> cell = f;
        if (side == 1) cell[a] -= 1;
        const std::size_t i = region.index(cell);
        if (region[i] < 0.0f && solid_[i] <= 0.5f) {
          u[lin] = static_cast<float>(velocity[a]);
          inflowThisStep_ = true;
        }
      });
    }
}

template <int D>
void LiquidSolver<D>::applyWallInflow() {
  if (inflowThisStep_ || inflowApplied_) {
    const MacGrid<D>* faces = inflowThisStep_ ? &*wallInflow_ : nullptr;
    projection_.setWallFaceVelocity(faces);  // also what extendVelocity gives the closed faces
    if (split_) split_->setWallFaceVelocity(faces);
  }
  inflowApplied_ = inflowThisStep_;
}

template <int D>
double LiquidSolver<D>::drain(const Grid<float, D>& region) {
  if (!region.sameLayout(phi_)) throw std::invalid_argument("liquid solver: drain needs a cell-centred region");
  if (!started_) start();
  ScopedStage s(timers_, "liquid: sinks");
  if (params_.tracker == InterfaceTracker::Flip) return flipVolume(flip_.removeInside(region));
  return -editLevelSet(region, [&](std::size_t i) { phi_[i] = std::max(phi_[i], -region[i]); });
}

template <int D>
template <typename Edit>
double LiquidSolver<D>::editLevelSet(const Grid<float, D>& region, Edit&& edit) {
  const double before = liquidVolume();
  parallelFor(0, phi_.count(), edit);
  particles_.removeInside(region);
  const double change = liquidVolume() - before;
  control_.target = std::max(0.0, control_.target + change);
  return change;
}

template <int D>
void LiquidSolver<D>::restore(const Grid<float, D>& phi, const MacGrid<D>& velocity, long steps) {
  if (!phi.sameLayout(phi_)) throw std::invalid_argument("liquid solver: restore needs a cell-centred phi");
  phi_ = phi;
  for (int a = 0; a < D; ++a) {
    if (!velocity.component(a).sameLayout(velocity_.component(a)))
      throw std::invalid_argument("liquid solver: restore needs the grid's face velocities");
    velocity_.component(a) = velocity.component(a);
  }
  steps_ = steps;
  started_ = true;
  const bool saved = particles_.size() > 0;  // the same on every process: each read the whole frame
  if (split_) {  // every process was given every saved particle: it keeps its own
    const auto foreign = [&](const auto& x) { return !owned_.contains(phi_.coord(spec_.clampedCellIndex(x))); };
    particles_.takeRowsIf(foreign);
    flip_.takeRowsIf(foreign);
  }
  if (params_.tracker == InterfaceTracker::ParticleLevelSet && !saved) particles_.seed(phi_);
  if (split_) exchangeParticles();
  resetVolumeControl();
}

template <int D>
double LiquidSolver<D>::liquidVolume() const {
  if (!split_) return numerics::enclosedVolume(phi_, &solid_);
  return split_->sumOverRanks(numerics::enclosedVolume(phi_, &solid_, &owned_));
}

template <int D>
void LiquidSolver<D>::resetVolumeControl() {
  control_ = VolumeControlState{};
  control_.target = liquidVolume();
}

template <int D>
void LiquidSolver<D>::reinitialize() {
  intoSolids_.extend(phi_);
  // Split: the block marches with its ghost layers filled (Selle ch. 8.1: ceil(band) layers give
  // the band's distances), then the ghosts take their owners' values.
  if (split_) split_->exchange(phi_);
  numerics::reinitializeFastMarching(phi_, params_.bandCells);
  if (split_) split_->exchange(phi_);
}

template <int D>
void LiquidSolver<D>::start() {
  reinitialize();
  extendVelocity();
  if (params_.tracker == InterfaceTracker::Flip) {
    flip_.seed(phi_, solid_, velocity_);
    if (split_) exchangeParticles();
    // Volume control holds the volume the particles' own surface has (it differs from the
    // given shape's by the reconstruction's bias; holding the other would move still water).
    flip_.surface(phi_, params_.bandCells);
    reinitialize();
  } else {
    particles_.seed(phi_);
    if (split_) exchangeParticles();  // the attraction may carry new particles over the block's edge
  }
  resetVolumeControl();
  started_ = true;
}

template <int D>
double LiquidSolver<D>::boundaryOutflow(double dt) const {
  double outflow = 0.0;
  const double faceArea = spec_.cellVolume() / spec_.dx;
  for (int a = 0; a < D; ++a) {
    // The faces of one side: the layer f[a] = 0 or res[a] of component a, visited as a grid of the
    // other axes (a split run: the owned ones of the domain's sides).
    IVec<D> layerSize = spec_.res;
    layerSize[a] = 1;
    const auto& u = velocity_.component(a);
    for (int side = 0; side < 2; ++side) {
      if (!onDomainSide(a, side)) continue;
      const double outward = side == 0 ? -1.0 : 1.0;
      std::size_t faces = 1;
      for (int b = 0; b < D; ++b) faces *= static_cast<std::size_t>(layerSize[b]);
      outflow += parallelSum(faces, [&](std::size_t k) {
        IVec<D> f;
        for (int b = 0; b < D; ++b) {
          f[b] = static_cast<int>(k % static_cast<std::size_t>(layerSize[b]));
          k /= static_cast<std::size_t>(layerSize[b]);
        }
        f[a] = side == 0 ? 0 : spec_.res[a];
        for (int b = 0; b < D; ++b)
          if (b != a && (f[b] < owned_.lo[b] || f[b] >= owned_.hi[b])) return 0.0;
        return faceTouches(a, f, [&](std::size_t cell) { return liquidCell(cell); }) ? outward * u(f) : 0.0;
      });
    }
  }
  if (split_) outflow = split_->sumOverRanks(outflow);
  return outflow * faceArea * dt;
}

template <int D>
double LiquidSolver<D>::volumeControlDivergence(double dt) {
  if (!params_.volumeControl) return 0.0;
  const double volume = volume_;
  if (params_.tracker == InterfaceTracker::Flip) {
    // FLIP's liquid is its particles: the target is their count, scaled by the ratio of the
    // rebuilt surface's volume to theirs when the control first saw them (the reconstruction's
    // bias; holding the particles' own volume instead would move still water). Emitters, sinks
    // and open sides change the count.
    const double particleVolume = flipVolume(flip_.size());
    if (control_.flipScale == 0.0 && particleVolume > 0.0) control_.flipScale = volume / particleVolume;
    control_.target = particleVolume * control_.flipScale;
  }
  if (!(control_.target > 0.0)) return 0.0;
  const double x = volume / control_.target - 1.0;
  control_.errorIntegral += x * dt;
  // The rate at which the surface lost volume in this step beyond what the last control asked
  // for (a splash hitting a wall loses several percent in a few steps, faster than the PI gains
  // follow): fed forward so that it is cancelled at once.
  double leak = 0.0;
  if (control_.started) leak = (x - control_.lastError) / dt - (control_.lastError + 1.0) * control_.divergence;
  control_.leakRate += 0.5 * (leak - control_.leakRate);
  control_.lastError = x;
  control_.started = true;
  // Kim et al. (2007) choose the gains so that an error decays, overdamped, within about 25 steps
  // (k_i = (k_p / 4.4)^2); a dam break's splashes need it faster (volumeControlSteps).
  const double kp = 2.3 / (params_.volumeControlSteps * dt), ki = (kp / 4.4) * (kp / 4.4);
  // At most 2% of the volume per step and 3 per second: a measurement that jumps (a drop leaving
  // the grid's reach) must not turn into a blast, and a bound that grew as the step shrinks would
  // feed itself (faster flow, shorter steps, a larger divergence allowed).
  const double limit = std::min(0.02 / dt, 3.0);
  return std::clamp(-(kp * x + ki * control_.errorIntegral + control_.leakRate) / (x + 1.0), -limit, limit);
}

template <int D>
double LiquidSolver<D>::cflTimestep() const {
  const double fastest = split_ ? split_->maxOverRanks(maxFaceSpeed(velocity_)) : maxFaceSpeed(velocity_);
  const double speed = fastest + std::sqrt(params_.gravity.norm() * spec_.dx);
  return speed > 0.0 ? params_.cfl * spec_.dx / speed : std::numeric_limits<double>::infinity();
}

template <int D>
int LiquidSolver<D>::advance(double dt) {
  const double limit = cflTimestep();
  const double needed = std::ceil(dt / limit);
  if (needed > params_.maxSubsteps)
    throw SimulationError(fmt::format(
        "liquid: step {} needs {} substeps of {:.3g} s for dt = {:.3g} s (more than time.max_substeps = {}): the "
        "liquid moves at {:.3g} m/s, {:.3g} cells per substep",
        steps_ + 1, needed, limit, dt, params_.maxSubsteps, params_.cfl * spec_.dx / limit, params_.cfl));
  const int n = std::max(1, static_cast<int>(needed));
  for (int i = 0; i < n; ++i) step(dt / n);
  return n;
}

template <int D>
void LiquidSolver<D>::moveSurface(double dt) {
  ScopedStage s(timers_, "liquid: surface");
  advector_.advect(phi_, velocity_, dt);
  particles_.advect(velocity_, dt);
  lastEscaped_ = particles_.correct(phi_);
  reinitialize();
  particles_.correct(phi_);
  particles_.adjustRadii(phi_);
  if ((steps_ + 1) % params_.reseedInterval == 0) particles_.reseed(phi_);
}

template <int D>
template <typename Tracked>
void LiquidSolver<D>::exchangeParticles(Tracked& particles, int reach) {
  constexpr int width = Tracked::kRowWidth;
  const auto cellOf = [&](const auto& x) { return phi_.coord(spec_.clampedCellIndex(x)); };
  std::vector<double> moved = particles.takeRowsIf([&](const auto& x) { return !owned_.contains(cellOf(x)); });
  split_->migrate(moved, width);
  particles.appendRows(moved);
  // The neighbours need the particles in the owned cells within `reach` of a block edge between
  // them (not on the domain's sides, where this block stores no ghosts).
  IndexBox<D> inner = owned_;
  for (int a = 0; a < D; ++a) {
    if (!onDomainSide(a, 0)) inner.lo[a] += reach;
    if (!onDomainSide(a, 1)) inner.hi[a] -= reach;
  }
  particles.setNeighbours(split_->neighbourRows(particles.rowsIf([&](const auto& x) {
    return !inner.contains(cellOf(x));
  }), width, reach));
}

template <int D>
void LiquidSolver<D>::exchangeParticles() {
  // A marker particle's correction touches the cell centres around it (its cell and the next);
  // FLIP's surface kernel reaches 2 cells (its splat onto the faces 1).
  if (params_.tracker == InterfaceTracker::Flip)
    exchangeParticles(flip_, 2);
  else
    exchangeParticles(particles_, 1);
}

template <int D>
double LiquidSolver<D>::flipVolume(std::size_t particles) const {
  const double own = flip_.particleVolume() * double(particles);
  return split_ ? split_->sumOverRanks(own) : own;
}

template <int D>
void LiquidSolver<D>::moveSplitSurface(double dt) {
  // Enright's step as moveSurface's, with the ghosts refilled before each stencil reads them: the
  // escaped test and the correction read phi around particles in the ghost layers, the radii and
  // reseeding around the own particles. An owned cell is corrected by every particle near it (its
  // own and the neighbours' copies, max and min in any order), so the corrections equal the serial
  // ones; the fast marching differs by what lies beyond the ghost layers.
  // phi's ghosts hold their owners' values from the last step's end (emitters and sinks edit every
  // cell alike), as its advection needs.
  ScopedStage s(timers_, "liquid: surface");
  advector_.advect(phi_, velocity_, dt);
  particles_.advect(velocity_, dt);
  exchangeParticles();
  split_->exchange(phi_);
  lastEscaped_ = particles_.correct(phi_);
  reinitialize();
  particles_.correct(phi_);
  split_->exchange(phi_);
  particles_.adjustRadii(phi_);
  if ((steps_ + 1) % params_.reseedInterval == 0) {
    particles_.reseed(phi_);
    exchangeParticles();
  }
}

template <int D>
void LiquidSolver<D>::moveFlipSurface(double dt) {
  ScopedStage s(timers_, "liquid: surface");
  flip_.advect(velocity_, dt, solidDistance_ ? &*solidDistance_ : nullptr, solid_, params_.sides);
  if (split_) exchangeParticles();
  flip_.surface(phi_, params_.bandCells);
  reinitialize();
}

template <int D>
void LiquidSolver<D>::extendVelocity() {
  ScopedStage s(timers_, "liquid: extend velocity");
  if (split_) split_->exchange(velocity_);  // the given faces in the ghost layers: their owners' values
  const MacGrid<D>& weights = projection_.faceWeights();
  const MacGrid<D>& solidVelocity = projection_.solidVelocity();
  for (int a = 0; a < D; ++a) {
    auto& u = velocity_.component(a);
    auto& known = known_[a];
    const auto& w = weights.component(a);
    resampleLinear(phi_, facePhi_[a]);
    // Given: open faces with liquid on a side (the pressure update set them).
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      known[lin] = w[lin] > 0.0f && faceTouches(a, f, [&](std::size_t cell) { return liquidCell(cell); });
    });
    numerics::extrapolateAlongNormals(u, known, facePhi_[a], params_.extrapolationCells);
    const auto& us = solidVelocity.component(a);
    parallelFor(0, u.count(), [&](std::size_t i) {
      if (w[i] <= 0.0f)
        u[i] = us[i];
      else if (!known[i])
        u[i] = 0.0f;
    });
  }
  if (split_) split_->exchange(velocity_);
}

template <int D>
void LiquidSolver<D>::step(double dt) {
  if (!(dt > 0.0) || !std::isfinite(dt)) throw std::invalid_argument(fmt::format("liquid solver: step of {} s", dt));
  if (!started_) start();
  const bool flip = params_.tracker == InterfaceTracker::Flip;
  if (params_.volumeControl && !flip) control_.target = std::max(0.0, control_.target - boundaryOutflow(dt));
  if (flip) {
    moveFlipSurface(dt);
    {
      ScopedStage s(timers_, "liquid: particles to grid");
      flip_.toGrid(velocity_);
    }
    extendVelocity();
    gridVelocityBefore_ = velocity_;
  } else {
    if (split_)
      moveSplitSurface(dt);
    else
      moveSurface(dt);
    ScopedStage s(timers_, "liquid: advect velocity");
    advector_.advect(velocity_, velocity_, dt);
  }
  {
    ScopedStage s(timers_, "liquid: gravity");
    for (int a = 0; a < D; ++a) {
      const float dv = static_cast<float>(params_.gravity[a] * dt);
      if (dv == 0.0f) continue;
      auto& u = velocity_.component(a);
      parallelFor(0, u.count(), [&](std::size_t i) { u[i] += dv; });
    }
  }
  if (vortex_) {
    // The particles' force (Selle ch. 3.4.2) joins gravity; none on faces next to obstacles.
    ScopedStage s(timers_, "liquid: vortex particles");
    vortex_->addForce(velocity_, dt, &solid_);
  }
  {
    ScopedStage s(timers_, "liquid: pressure");
    parallelFor(0, phi_.count(), [&](std::size_t i) {  // solids hold no liquid (their faces are closed)
      pressurePhi_[i] = solid_[i] > 0.5f ? std::max(phi_[i], static_cast<float>(0.5 * spec_.dx)) : phi_[i];
    });
    volume_ = liquidVolume();  // phi is final for this step from here on
    control_.divergence = volumeControlDivergence(dt);
    applyWallInflow();
    if (split_) {
      split_->setFreeSurface(pressurePhi_);
      split_->setTargetDivergence(control_.divergence);
      const SplitSolveStats solve = split_->project(velocity_, projection_.pressure(), dt, params_.density);
      lastSolve_.iterations = solve.iterations;
      lastSolve_.relativeResidual = solve.relativeResidual;
      lastSolve_.converged = solve.converged;
    } else {
      projection_.setFreeSurface(pressurePhi_);
      projection_.setTargetDivergence(control_.divergence);
      lastSolve_ = projection_.project(velocity_, dt, params_.density);
    }
  }
  extendVelocity();
  if (flip) {
    ScopedStage s(timers_, "liquid: grid to particles");
    flip_.fromGrid(velocity_, gridVelocityBefore_, params_.flipRatio);
  }
  if (vortex_) advanceVortexParticles(dt);
  if (inflowThisStep_) {  // the emitters mark their wall faces again before the next step
    for (int a = 0; a < D; ++a) wallInflow_->component(a).fill(0.0f);
    inflowThisStep_ = false;
  }
  ++steps_;
  time_ += dt;
  if (split_) checkFiniteSplit();
}

template <int D>
void LiquidSolver<D>::checkFiniteSplit() const {
  bool finite = allFinite(phi_.data());
  for (int a = 0; a < D; ++a) finite = finite && allFinite(velocity_.component(a).data());
  if (split_->maxOverRanks(finite ? 0.0 : 1.0) != 0.0)
    throw SimulationError(fmt::format("liquid: non-finite phi or velocity at step {} (on some process)", steps_));
}

template <int D>
void LiquidSolver<D>::setVortexLayer(std::unique_ptr<VortexLayer<D>> layer) {
  vortex_ = std::move(layer);
  if (!vortex_) return;
  vortex_->setDomainSplit(split_);
  if (solidDistance_) vortex_->setSolid(*solidDistance_);
  vortex_->seedInitial(vortex_->flowVorticity(velocity_));
  dropVortexParticlesInAir();
}

template <int D>
void LiquidSolver<D>::advanceVortexParticles(double dt) {
  ScopedStage s(timers_, "liquid: vortex particles");
  vortex_->advance(velocity_, dt, time_, vortex_->flowVorticity(velocity_));
  dropVortexParticlesInAir();
}

template <int D>
void LiquidSolver<D>::dropVortexParticlesInAir() {
  // phi > 0 (read D-linearly at the cell centres) is air, which carries no vorticity.
  vortex_->removeWherePositive(phi_);
}

template <int D>
LiquidStatistics LiquidSolver<D>::statistics() const {
  // A split run sums over the processes' own cells and particles (every process calls this).
  LiquidStatistics s;
  s.volume = liquidVolume();
  s.targetVolume = control_.target;
  s.controlDivergence = control_.divergence;
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    s.maxSpeed = std::max(s.maxSpeed, parallelMax(u.count(), [&](std::size_t i) {
                            const bool wet = faceTouches(a, u.coord(i), [&](std::size_t cell) { return liquidCell(cell); });
                            return wet ? std::abs(u[i]) : 0.0f;
                          }));
  }
  const auto ownLiquidCell = [&](std::size_t cell) { return liquidCell(cell) && owned_.contains(phi_.coord(cell)); };
  s.kineticEnergy = 0.5 * params_.density * spec_.cellVolume() * parallelSum(phi_.count(), [&](std::size_t i) {
                      if (!ownLiquidCell(i)) return 0.0;
                      const IVec<D> c = phi_.coord(i);
                      double e = 0.0;
                      for (int a = 0; a < D; ++a) {
                        IVec<D> up = c;
                        up[a] += 1;
                        const double v = 0.5 * (velocity_.component(a)(c) + velocity_.component(a)(up));
                        e += v * v;
                      }
                      return e;
                    });
  s.pressureIterations = lastSolve_.iterations;
  s.pressureConverged = lastSolve_.converged;
  Vorticity<D> vorticity(spec_);
  computeVorticity(velocity_, vorticity);
  s.enstrophy = enstrophy<D>(vorticity, ownLiquidCell);
  s.vortexParticles = vortex_ ? vortex_->particles().size() : 0;
  s.particles = params_.tracker == InterfaceTracker::Flip ? flip_.size() : particles_.size();
  s.escaped = lastEscaped_;
  s.step = steps_;
  if (split_) {
    s.maxSpeed = split_->maxOverRanks(s.maxSpeed);
    std::array<double, 4> sums = {s.kineticEnergy, s.enstrophy, double(s.particles), double(s.escaped)};
    split_->sumOverRanks(sums);
    s.kineticEnergy = sums[0];
    s.enstrophy = sums[1];
    s.particles = static_cast<std::size_t>(sums[2]);
    s.escaped = static_cast<std::size_t>(sums[3]);
  }
  return s;
}

template class LiquidSolver<2>;
template class LiquidSolver<3>;

}  // namespace msim::fluid
