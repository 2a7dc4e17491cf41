#include "msim/fluid/smoke/smoke_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"

namespace msim::fluid {

template <int D>
SmokeSolver<D>::SmokeSolver(const GridSpec<D>& spec, const SmokeParams<D>& params)
    : spec_(spec),
      params_(params),
      velocity_(spec, 0.0f),
      density_(spec, 0.0f),
      temperature_(spec, static_cast<float>(params.buoyancy.ambientTemperature)),
      solid_(spec, 0.0f),
      divergence_(spec, 0.0f),
      sealed_(spec, 0.0f),
      advector_(spec, params.advection),
      projection_(spec, params.sides, params.projection),
      confinement_(spec),
      viscosity_(spec) {
  // The normal part of a wall's velocity feeds or drains the domain (Selle ch. 2.9's tunnel); the
  // tangential part drags the fluid through the viscous term (a cavity lid).
  for (int a = 0; a < D; ++a)
    for (int side = 0; side < 2; ++side) projection_.setWallNormalVelocity(a, side, params.wallVelocity[a][side][a]);
  updateSealed();
}

template <int D>
void SmokeSolver<D>::setObstacles(const Grid<float, D>& nodalSolidPhi) {
  projection_.setSolids(numerics::openFaceFractions<D>(spec_, nodalSolidPhi));
  if (split_) split_->setOpenFractions(projection_.faceWeights());
  numerics::solidCellsFromNodes(nodalSolidPhi, solid_);  // solid for advection and forces
  advector_.setSolid(solid_);
  updateSealed();
  findCutFaces();
  if (conservative_) conservative_->transport.setSolid(sealed_);
  hasObstacles_ = true;
  border_ = numerics::SolidExtension<D>(solid_, 1);
  if (vortex_) vortex_->setSolid(nodalSolidPhi);
}

template <int D>
void SmokeSolver<D>::setVortexLayer(std::unique_ptr<VortexLayer<D>> layer) {
  vortex_ = std::move(layer);
  if (vortex_ && split_) vortex_->setDomainSplit(split_);
  if (vortex_) vortex_->seedInitial(vortex_->flowVorticity(velocity_));
}

template <int D>
void SmokeSolver<D>::findCutFaces() {
  const MacGrid<D>& weights = projection_.faceWeights();
  for (int a = 0; a < D; ++a) {
    CutFaces& cut = cutFaces_[a];
    cut.faces.clear();
    cut.start.assign(1, 0);
    cut.neighbours.clear();
    const Grid<float, D>& w = weights.component(a);
    // The advector's rule: a face of a solid cell is solid (kept as it is).
    auto advectorSolid = [&](const IVec<D>& f) {
      IVec<D> below = f;
      below[a] -= 1;
      return (solid_.inside(f) && solid_(f) > 0.5f) || (solid_.inside(below) && solid_(below) > 0.5f);
    };
    for (std::size_t i = 0; i < w.count(); ++i) {
      const IVec<D> f = w.coord(i);
      if (!(w[i] > 0.0f) || !advectorSolid(f)) continue;
      cut.faces.push_back(i);
      for (int b = 0; b < D; ++b)
        for (int step : {-1, 1}) {
          IVec<D> nb = f;
          nb[b] += step;
          if (w.inside(nb) && w(nb) > 0.0f && !advectorSolid(nb)) cut.neighbours.push_back(w.index(nb));
        }
      cut.start.push_back(cut.neighbours.size());
    }
  }
}

template <int D>
void SmokeSolver<D>::extrapolateIntoCutFaces() {
  for (int a = 0; a < D; ++a) {
    const CutFaces& cut = cutFaces_[a];
    Grid<float, D>& u = velocity_.component(a);
    const Grid<float, D>& us = projection_.solidVelocity().component(a);
    parallelFor(0, cut.faces.size(), [&](std::size_t k) {
      const std::size_t begin = cut.start[k], end = cut.start[k + 1];
      double sum = 0.0;
      for (std::size_t j = begin; j < end; ++j) sum += u[cut.neighbours[j]];
      u[cut.faces[k]] = end > begin ? static_cast<float>(sum / static_cast<double>(end - begin)) : us[cut.faces[k]];
    }, 256);
  }
}

template <int D>
void SmokeSolver<D>::updateSealed() {
  const MacGrid<D>& w = projection_.faceWeights();
  parallelForCells(sealed_, [&](const IVec<D>& c, std::size_t lin) {
    bool open = false;
    for (int a = 0; a < D && !open; ++a) {
      IVec<D> upper = c;
      upper[a] += 1;
      open = w.component(a)(c) > 0.0f || w.component(a)(upper) > 0.0f;
    }
    sealed_[lin] = open ? 0.0f : 1.0f;
  });
}

template <int D>
void SmokeSolver<D>::setObstacleVelocity(const MacGrid<D>& solidVelocity) {
  projection_.setSolidVelocity(solidVelocity);
  if (split_) split_->setSolidVelocity(solidVelocity);
}

template <int D>
std::size_t SmokeSolver<D>::addScalar(std::string name, double dissipation, float initial) {
  scalars_.push_back(Scalar{std::move(name), dissipation, Grid<float, D>(spec_, initial)});
  return scalars_.size() - 1;
}

template <int D>
double SmokeSolver<D>::cflTimestep() const {
  const double speed = split_ ? split_->maxOverRanks(maxFaceSpeed(velocity_)) : maxFaceSpeed(velocity_);
  double dt = speed > 0.0 ? params_.cfl * spec_.dx / speed : std::numeric_limits<double>::infinity();
  // Explicit diffusion is stable for nu dt / dx^2 <= 1 / (2 D) (the Laplacian's largest eigenvalue).
  if (params_.viscosity > 0.0 && params_.viscosityMode == ViscosityMode::Explicit)
    dt = std::min(dt, spec_.dx * spec_.dx / (2.0 * D * params_.viscosity));
  return dt;
}

template <int D>
int SmokeSolver<D>::advance(double dt) {
  const double limit = cflTimestep();
  const int n = std::clamp(static_cast<int>(std::ceil(dt / limit)), 1, std::max(1, params_.maxSubsteps));
  for (int i = 0; i < n; ++i) step(dt / n);
  return n;
}

template <int D>
void SmokeSolver<D>::setDomainSplit(DomainSplit<D>* split) {
  split_ = split;
  advector_.setPlacement(split ? split->placement() : BlockPlacement<D>{});
  if (vortex_) vortex_->setDomainSplit(split);
  if (split_)
    for (int a = 0; a < D; ++a)
      for (int side = 0; side < 2; ++side) split_->setWallNormalVelocity(a, side, params_.wallVelocity[a][side][a]);
  // Obstacles placed before: the split's solve takes them too (its own walls by global index).
  if (split_ && hasObstacles_) {
    split_->setOpenFractions(projection_.faceWeights());
    split_->setSolidVelocity(projection_.solidVelocity());
  }
}

template <int D>
void SmokeSolver<D>::checkDistributable() const {
  auto refuse = [](const std::string& what) {
    throw InputError("smoke split among MPI processes: " + what + " is not distributed; run it on one process");
  };
  if (advectionOffset_ || scalarsElsewhere_) refuse("procedural turbulence");
}

template <int D>
void SmokeSolver<D>::step(double dt) {
  const Grid<float, D>* solid = hasObstacles_ ? &solid_ : nullptr;
  if (split_) checkDistributable();
  {
    ScopedStage s(timers_, "sources");
    if (params_.scalarTransport == ScalarTransport::Advector) resetInflowCells();
    applyScalarSources(dt);
  }
  {
    // Self-advection of the momentum, the (u.grad) u term of eq. 3.1.
    ScopedStage s(timers_, "advect velocity");
    if (advectionOffset_) {
      if (!advecting_) advecting_.emplace(spec_);
      for (int a = 0; a < D; ++a) {
        auto& w = advecting_->component(a);
        const auto& u = velocity_.component(a);
        const auto& o = advectionOffset_->component(a);
        parallelFor(0, w.count(), [&](std::size_t i) { w[i] = u[i] + o[i]; }, 1 << 14);
      }
      advector_.advect(velocity_, *advecting_, dt);
    } else {
      if (split_) split_->exchange(velocity_);
      advector_.advect(velocity_, velocity_, dt);
    }
    // Faces the projection treats as (partly) fluid but the advector as solid keep their old value
    // there; refresh them from the fluid beside them, or the pressure correction would pile up on
    // them step after step and the velocity would grow without bound.
    if (hasObstacles_) extrapolateIntoCutFaces();
  }
  {
    ScopedStage s(timers_, "forces");
    const auto& b = params_.buoyancy;
    if (split_) {
      // Buoyancy averages cells to faces, confinement differences the velocity twice. Density and
      // temperature change next only in their advection, so these ghosts serve it too.
      split_->exchange(velocity_);
      split_->exchange(density_);
      split_->exchange(temperature_);
    }
    if (b.alpha != 0.0 || b.beta != 0.0) addBuoyancy(velocity_, density_, temperature_, b, dt, solid);
    // Confinement re-injects the small-scale rotation (eq. 3.3) numerical dissipation removed.
    if (params_.vorticityEpsilon != 0.0) confinement_.apply(velocity_, params_.vorticityEpsilon, dt, solid);
    // The vortex particles' force (Selle ch. 3.4.2), a body force that keeps the total vorticity.
    if (vortex_) vortex_->addForce(velocity_, dt, solid);
    if (!winds_.empty()) applyWinds(dt);
  }
  if (params_.viscosity > 0.0) {
    ScopedStage s(timers_, "viscosity");
    const ViscosityBoundaries<D> walls{params_.sides, params_.wallSlip, params_.wallVelocity};
    viscosityIterations_ = viscosity_.apply(velocity_, projection_.faceWeights(), walls, params_.viscosity, dt,
                                            params_.viscosityMode, params_.viscositySolve, split_);
  }
  {
    // Eq. 3.2 through the pressure: inflow faces are set first so the projection balances them.
    ScopedStage s(timers_, "project");
    applyInflow();
    updateExpansion();
    if (split_) {
      pressureIterations_ = split_->project(velocity_, projection_.pressure(), dt, params_.fluidDensity).iterations;
      split_->exchange(velocity_);  // the divergence below and the scalars' advection read ghosts
    } else {
      pressureIterations_ = projection_.project(velocity_, dt, params_.fluidDensity).iterations;
    }
    maxDivergence_ = measureDivergence();
  }
  if (vortex_) {
    // The particles move with the divergence-free velocity (Selle ch. 3.3).
    ScopedStage s(timers_, "vortex particles");
    vortex_->advance(velocity_, dt, time_, vortex_->flowVorticity(velocity_));
  }
  {
    ScopedStage s(timers_, "advect scalars");
    if (params_.scalarTransport == ScalarTransport::Conservative)
      transportScalarsConservatively(dt);
    else
      advectScalars(dt);
    dissipate(dt);
  }
  ++steps_;
  time_ += dt;
  if (params_.checkFinite) checkFinite();
}

template <int D>
void SmokeSolver<D>::advectScalars(double dt) {
  if (!scalarsElsewhere_)
    for (Grid<float, D>* f : {&density_, &temperature_}) {
      border_.extend(*f);  // a split run filled their ghosts before the forces
      advector_.advect(*f, velocity_, dt);
    }
  for (auto& sc : scalars_) {
    if (split_) split_->exchange(sc.field);
    border_.extend(sc.field);
    advector_.advect(sc.field, velocity_, dt);
  }
}

template <int D>
void SmokeSolver<D>::transportScalarsConservatively(double dt) {
  if (!conservative_) {
    // Open domain sides, and walls that move fluid in or out (normal wall velocity), let the
    // scalars out with their upwind value and bring in the background (see below); other walls
    // are closed.
    numerics::TransportBoundaries<D> boundaries;
    for (int a = 0; a < D; ++a)
      for (int side = 0; side < 2; ++side)
        boundaries.side[a][side] = params_.sides.side[a][side] == numerics::DomainSide::Open ||
                                           params_.wallVelocity[a][side][a] != 0.0
                                       ? numerics::BoundaryKind::Open
                                       : numerics::BoundaryKind::Closed;
    conservative_ = std::make_unique<Conservative>(
        Conservative{numerics::FluxTransport<D>(spec_, boundaries), MacGrid<D>(spec_, 0.0f)});
    conservative_->transport.setSolid(sealed_);
  }
  // The carrying velocity is the fluid volume flux w_f u_f of the projection (Batty et al. 2007;
  // PressureProjection's F_f less the solid part (1 - w_f) u_solid), not u_f itself:
  //  - for static obstacles sum_faces w_f u_f = dx div(u) = 0 in every cell with an open face, to
  //    the PCG tolerance, so in flux form a uniform field stays uniform and the limited MUSCL
  //    scheme keeps the maximum principle up to the obstacle surface. The bare u_f is not
  //    divergence free in cut cells (it over-counts the area of partly covered faces) and would
  //    pile smoke up against obstacles.
  //  - a fully covered face (w = 0) carries nothing even where the projection gave it the
  //    obstacle's velocity: smoke never passes through a solid. Domain walls are the exception:
  //    their faces (w = 0) hold the wall's normal velocity, the volume that enters or leaves
  //    there, and carry it, so an outflow wall lets smoke out instead of piling it up.
  //  - cells without an open face (sealed_) are the transport's solids; cells whose centre is in
  //    the obstacle but that have open faces hold smoke like any other cell. Masking them by the
  //    centre test (solid_) would zero their faces and break div = 0 in their neighbours.
  // Conservation holds whatever the velocity: each interior face moves what one cell loses into
  // its neighbour, and walls and sealed cells have no flux. Moving obstacles change the fluid
  // volume of cut cells, which fixed cell volumes cannot follow: there sum w u != 0 and uniform
  // fields are kept only approximately (the total still exactly).
  Conservative& c = *conservative_;
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    const auto& w = projection_.faceWeights().component(a);
    auto& flux = c.faceVelocity.component(a);
    const int last = spec_.res[a];
    const auto& side = params_.sides.side[a];
    parallelForCells(flux, [&](const IVec<D>& f, std::size_t i) {
      const bool wall = (f[a] == 0 && side[0] == numerics::DomainSide::Wall) ||
                        (f[a] == last && side[1] == numerics::DomainSide::Wall);
      flux[i] = wall ? u[i] : w[i] * u[i];
    });
  }
  c.transport.setVelocity(c.faceVelocity);
  // FluxTransport is positivity preserving for sum_a |u_a| dt / dx <= 1/2 (MUSCL + SSP-RK2), up
  // to 2 D times stricter than the step's CFL limit: sub-cycle in equal steps.
  // Split runs: every rank takes the same substeps, and each substep starts from filled ghosts
  // (two stages of MUSCL read four cells: parallel/ghost_layers.hpp).
  const double local = c.transport.maxStableDt(0.0);
  const double limit = split_ ? -split_->maxOverRanks(-local) : local;
  const int n = std::max(1, static_cast<int>(std::ceil(dt / limit)));
  const double h = dt / n;
  const numerics::TransportSettings zeroBackground{numerics::TransportForm::Conservative, 0.0, 0.0};
  auto transport = [&](Grid<float, D>& field) {
    for (int k = 0; k < n; ++k) {
      if (split_) split_->exchange(field);
      c.transport.step(field, zeroBackground, h);
    }
  };
  // Every field is moved as its excess over a background that is 0 at open-side inflow: density
  // and the extra scalars (which dissipate towards 0) as they are, temperature as T - T_ambient.
  // In flux form a constant c changes at the rate -c div u, and div u is zero only to the PCG
  // tolerance: moving the excess keeps ambient air exactly ambient (and spends float precision
  // on the excess, not on the ~300 K offset). The offset is affine, so the total of T is still
  // conserved and inflowing air is at ambient temperature.
  transport(density_);
  const float ambient = static_cast<float>(params_.buoyancy.ambientTemperature);
  parallelFor(0, temperature_.count(), [&](std::size_t i) { temperature_[i] -= ambient; });
  transport(temperature_);
  parallelFor(0, temperature_.count(), [&](std::size_t i) { temperature_[i] += ambient; });
  for (auto& sc : scalars_) transport(sc.field);
}

template <int D>
void SmokeSolver<D>::resetInflowCells() {
  // The back-traces of cells on the domain boundary that leave the grid read the boundary cell
  // itself (clamped). Where air flows in, that would keep whatever smoke once touched the side
  // there forever; instead the cell holds the incoming air's values (no smoke, ambient
  // temperature), a first-order inflow condition. Sources applied after this still set theirs.
  const float ambient = static_cast<float>(params_.buoyancy.ambientTemperature);
  for (int a = 0; a < D; ++a) {
    const Grid<float, D>& u = velocity_.component(a);
    IVec<D> across = spec_.res;
    across[a] = 1;
    std::size_t count = 1;
    for (int b = 0; b < D; ++b) count *= static_cast<std::size_t>(across[b]);
    for (int side = 0; side < 2; ++side) {
      parallelFor(0, count, [&](std::size_t k) {
        IVec<D> c;
        std::size_t rest = k;
        for (int b = 0; b < D; ++b) {
          c[b] = static_cast<int>(rest % static_cast<std::size_t>(across[b]));
          rest /= static_cast<std::size_t>(across[b]);
        }
        c[a] = side == 0 ? 0 : spec_.res[a] - 1;
        IVec<D> face = c;
        face[a] += side;
        const float inward = side == 0 ? u(face) : -u(face);
        if (!(inward > 0.0f)) return;
        const std::size_t cell = density_.index(c);
        density_[cell] = 0.0f;
        temperature_[cell] = ambient;
        for (auto& sc : scalars_) sc.field[cell] = 0.0f;
      }, 64);
    }
  }
}

template <int D>
void SmokeSolver<D>::applyScalarSources(double dt) {
  for (const auto& src : sources_)
    applySourceScalars<D>(src, dt, density_, temperature_, [&](std::size_t i) -> Grid<float, D>& { return scalars_[i].field; });
}

template <int D>
void SmokeSolver<D>::applyInflow() {
  for (const auto& src : sources_) {
    if (!src.active || !src.velocity) continue;
    const Vec<D> v = *src.velocity;
    // Two cells of one source share faces; blending one face twice with the same target is
    // harmless, so the loop stays sequential only to keep the result independent of scheduling.
    for (const auto& [cell, w] : src.cells) {
      const IVec<D> c = density_.coord(cell);
      for (int a = 0; a < D; ++a) {
        auto& u = velocity_.component(a);
        IVec<D> hi = c;
        hi[a] += 1;
        for (const IVec<D>& f : {c, hi}) u(f) += static_cast<float>(w * (v[a] - u(f)));
      }
    }
  }
}

template <int D>
void SmokeSolver<D>::updateExpansion() {
  const bool expanding = std::any_of(sources_.begin(), sources_.end(),
                                     [](const SmokeSource<D>& s) { return s.active && s.expansion != 0.0; });
  if (!expanding) {
    if (expansion_.count() != 0) {
      expansion_ = Grid<float, D>();
      projection_.setCellTargetDivergence(nullptr);
      if (split_) split_->setCellTargetDivergence(nullptr);
    }
    return;
  }
  if (expansion_.count() == 0) expansion_ = Grid<float, D>(spec_);
  std::fill(expansion_.data().begin(), expansion_.data().end(), 0.0f);
  for (const auto& src : sources_)
    if (src.active)
      for (const auto& [cell, w] : src.cells) expansion_[cell] += static_cast<float>(w * src.expansion);
  projection_.setCellTargetDivergence(&expansion_);
  if (split_) split_->setCellTargetDivergence(&expansion_);
}

template <int D>
void dissipateSmoke(Grid<float, D>& density, Grid<float, D>& temperature, double densityRate, double temperatureRate,
                    double ambientTemperature, double dt) {
  const float keepRho = static_cast<float>(std::exp(-densityRate * dt));
  const float keepT = static_cast<float>(std::exp(-temperatureRate * dt));
  const float ambient = static_cast<float>(ambientTemperature);
  if (keepRho != 1.0f || keepT != 1.0f)
    parallelFor(0, density.count(), [&](std::size_t i) {
      density[i] *= keepRho;
      temperature[i] = ambient + (temperature[i] - ambient) * keepT;
    }, 1 << 14);
}

template <int D>
void SmokeSolver<D>::dissipate(double dt) {
  if (!scalarsElsewhere_)
    dissipateSmoke<D>(density_, temperature_, params_.densityDissipation, params_.temperatureDissipation,
                      params_.buoyancy.ambientTemperature, dt);
  for (auto& sc : scalars_) {
    const float keep = static_cast<float>(std::exp(-sc.dissipation * dt));
    if (keep != 1.0f) parallelFor(0, sc.field.count(), [&](std::size_t i) { sc.field[i] *= keep; });
  }
}

template <int D>
double SmokeSolver<D>::measureDivergence() {
  projection_.divergence(velocity_, divergence_);
  // Expanding sources keep their divergence on purpose; what is measured is the error.
  const bool expanding = expansion_.count() != 0;
  const auto error = [&](std::size_t i) { return std::abs(double(divergence_[i]) - (expanding ? expansion_[i] : 0.0)); };
  if (!split_) return parallelMax(divergence_.count(), error);
  // A split run: the owned cells (the local face weights are right on all their faces, a block's
  // edge lying a ghost layer away), over every rank.
  const IndexBox<D> own = split_->owned();
  const double worst =
      parallelMax(divergence_.count(), [&](std::size_t i) { return own.contains(divergence_.coord(i)) ? error(i) : 0.0; });
  return split_->maxOverRanks(worst);
}

template <int D>
void SmokeSolver<D>::checkFinite() const {
  auto fail = [&](const std::string& field) {
    throw SimulationError("smoke solver: non-finite " + field + " at step " + std::to_string(steps_));
  };
  // A split run agrees on every field before throwing, so that every rank stops together.
  auto finite = [&](const std::vector<float>& v) {
    const bool here = allFinite(v);
    return split_ ? split_->maxOverRanks(here ? 0.0 : 1.0) == 0.0 : here;
  };
  static const char* axisName[] = {"x", "y", "z"};
  for (int a = 0; a < D; ++a)
    if (!finite(velocity_.component(a).data())) fail(std::string("velocity ") + axisName[a]);
  if (!finite(density_.data())) fail("density");
  if (!finite(temperature_.data())) fail("temperature");
  for (const auto& sc : scalars_)
    if (!finite(sc.field.data())) fail("scalar '" + sc.name + "'");
}

template <int D>
void measureSmoke(const MacGrid<D>& velocity, const MacGrid<D>* weights, const Grid<float, D>& density,
                  const Grid<float, D>* excluded, double fluidDensity, SmokeStatistics& s) {
  s.kineticEnergy = 0.0;
  const GridSpec<D>& spec = velocity.spec();
  const double dV = spec.cellVolume();
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity.component(a);
    const float* w = weights ? weights->component(a).data().data() : nullptr;
    s.kineticEnergy += 0.5 * fluidDensity * dV * parallelSum(u.count(), [&](std::size_t i) {
      return (w ? double(w[i]) : 1.0) * u[i] * u[i];
    });
  }
  s.maxSpeed = maxFaceSpeed(velocity);
  s.totalDensity = dV * parallelSum(density.count(), [&](std::size_t i) {
    return excluded && (*excluded)[i] > 0.5f ? 0.0 : double(density[i]);
  });
  Vorticity<D> vorticity(spec);
  computeVorticity(velocity, vorticity);
  s.enstrophy = enstrophy<D>(vorticity, [](std::size_t) { return true; });
}

template <int D>
SmokeStatistics SmokeSolver<D>::statistics() const {
  // The cells each transport keeps scalars in: the Advector overwrites solid cells with their
  // neighbours' mean every step, the conservative transport owns every cell with an open face.
  const Grid<float, D>& excluded = params_.scalarTransport == ScalarTransport::Conservative ? sealed_ : solid_;
  SmokeStatistics s = counters();
  measureSmoke<D>(velocity_, &projection_.faceWeights(), density_, &excluded, params_.fluidDensity, s);
  return s;
}

template <int D>
SmokeStatistics SmokeSolver<D>::counters() const {
  SmokeStatistics s;
  s.vortexParticles = vortex_ ? vortex_->particles().size() : 0;
  s.maxDivergence = maxDivergence_;
  s.pressureIterations = pressureIterations_;
  s.viscosityIterations = viscosityIterations_;
  s.step = steps_;
  return s;
}

template <int D>
double SmokeSolver<D>::maxWindSpeed() const {
  double sum = 0.0;
  for (const auto& w : winds_) sum += w.maxSpeed();
  return sum;
}

// Drag towards the winds, du/dt = c (u_wind - u), solved exactly over the step (stable for any c
// dt), on the faces between two fluid cells, with the winds at the middle of the step.
template <int D>
void SmokeSolver<D>::applyWinds(double dt) {
  const float pull = static_cast<float>(1.0 - std::exp(-params_.windCoupling * dt));
  if (pull == 0.0f) return;
  const double t = time_ + 0.5 * dt;
  for (int a = 0; a < D; ++a) {
    auto& u = velocity_.component(a);
    windScratch_.resize(u.count());
    std::fill(windScratch_.begin(), windScratch_.end(), 0.0f);
    for (const auto& w : winds_) w.forEachSample(u, a, t, [&](std::size_t lin, float v) { windScratch_[lin] += v; });
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (hasObstacles_) {
        IVec<D> below = f;
        below[a] -= 1;
        const bool solidBelow = below[a] >= 0 && solid_(below) > 0.5f;
        const bool solidAbove = f[a] < spec_.res[a] && solid_(f) > 0.5f;
        if (solidBelow || solidAbove) return;
      }
      u[lin] += pull * (windScratch_[lin] - u[lin]);
    });
  }
}

template void measureSmoke<2>(const MacGrid<2>&, const MacGrid<2>*, const Grid<float, 2>&, const Grid<float, 2>*,
                              double, SmokeStatistics&);
template void measureSmoke<3>(const MacGrid<3>&, const MacGrid<3>*, const Grid<float, 3>&, const Grid<float, 3>*,
                              double, SmokeStatistics&);
template void dissipateSmoke<2>(Grid<float, 2>&, Grid<float, 2>&, double, double, double, double);
template void dissipateSmoke<3>(Grid<float, 3>&, Grid<float, 3>&, double, double, double, double);
template class SmokeSolver<2>;
template class SmokeSolver<3>;

}  // namespace msim::fluid
