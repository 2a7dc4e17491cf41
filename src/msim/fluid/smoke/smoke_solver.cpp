#include "msim/fluid/smoke/smoke_solver.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/numerics/pressure/face_fractions.hpp"

namespace msim::fluid {

namespace {

bool allFinite(const std::vector<float>& v) {
  return parallelMax(v.size(), [&](std::size_t i) { return std::isfinite(v[i]) ? 0.0 : 1.0; }) == 0.0;
}

}  // namespace

template <int D>
SmokeSolver<D>::SmokeSolver(const GridSpec<D>& spec, const SmokeParams<D>& params)
    : spec_(spec),
      params_(params),
      velocity_(spec, 0.0f),
      density_(spec, 0.0f),
      temperature_(spec, static_cast<float>(params.buoyancy.ambientTemperature)),
      solid_(spec, 0.0f),
      divergence_(spec, 0.0f),
      advector_(spec, params.advection),
      projection_(spec, params.sides, params.projection),
      confinement_(spec),
      viscosity_(spec) {}

template <int D>
void SmokeSolver<D>::setObstacles(const Grid<float, D>& nodalSolidPhi) {
  projection_.setSolids(numerics::openFaceFractions<D>(spec_, nodalSolidPhi));
  // A cell is solid for advection and forces when the D-linear interpolant of phi is negative at
  // its centre, i.e. the mean of its 2^D corners.
  parallelForCells(solid_, [&](const IVec<D>& c, std::size_t lin) {
    double phi = 0.0;
    for (int k = 0; k < (1 << D); ++k) {
      IVec<D> n = c;
      for (int a = 0; a < D; ++a) n[a] += (k >> a) & 1;
      phi += nodalSolidPhi(n);
    }
    solid_[lin] = phi < 0.0 ? 1.0f : 0.0f;
  });
  advector_.setSolid(solid_);
  hasObstacles_ = true;
  borderCells_.clear();
  borderStart_.assign(1, 0);
  borderNeighbours_.clear();
  for (std::size_t i = 0; i < solid_.count(); ++i) {
    if (solid_[i] <= 0.5f) continue;
    const IVec<D> c = solid_.coord(i);
    const std::size_t first = borderNeighbours_.size();
    for (int a = 0; a < D; ++a)
      for (int s : {-1, 1}) {
        IVec<D> nb = c;
        nb[a] += s;
        if (solid_.inside(nb) && solid_(nb) <= 0.5f) borderNeighbours_.push_back(solid_.index(nb));
      }
    if (borderNeighbours_.size() > first) {
      borderCells_.push_back(i);
      borderStart_.push_back(borderNeighbours_.size());
    }
  }
}

template <int D>
void SmokeSolver<D>::setObstacleVelocity(const MacGrid<D>& solidVelocity) {
  projection_.setSolidVelocity(solidVelocity);
}

template <int D>
std::size_t SmokeSolver<D>::addScalar(std::string name, double dissipation, float initial) {
  scalars_.push_back(Scalar{std::move(name), dissipation, Grid<float, D>(spec_, initial)});
  return scalars_.size() - 1;
}

template <int D>
double SmokeSolver<D>::cflTimestep() const {
  double speed = 0.0;
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    speed = std::max(speed, parallelMax(u.count(), [&](std::size_t i) { return std::abs(u[i]); }));
  }
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
void SmokeSolver<D>::step(double dt) {
  const Grid<float, D>* solid = hasObstacles_ ? &solid_ : nullptr;
  {
    ScopedStage s(timers_, "sources");
    applyScalarSources(dt);
  }
  {
    // Self-advection of the momentum, the (u.grad) u term of eq. 3.1.
    ScopedStage s(timers_, "advect velocity");
    advector_.advect(velocity_, velocity_, dt);
  }
  {
    ScopedStage s(timers_, "forces");
    const auto& b = params_.buoyancy;
    if (b.alpha != 0.0 || b.beta != 0.0) addBuoyancy(velocity_, density_, temperature_, b, dt, solid);
    // Confinement re-injects the small-scale rotation (eq. 3.3) numerical dissipation removed.
    if (params_.vorticityEpsilon != 0.0) confinement_.apply(velocity_, params_.vorticityEpsilon, dt, solid);
  }
  if (params_.viscosity > 0.0) {
    ScopedStage s(timers_, "viscosity");
    const ViscosityBoundaries<D> walls{params_.sides, params_.wallSlip, params_.wallVelocity};
    viscosityIterations_ = viscosity_.apply(velocity_, projection_.faceWeights(), walls, params_.viscosity, dt,
                                            params_.viscosityMode, params_.viscositySolve);
  }
  {
    // Eq. 3.2 through the pressure: inflow faces are set first so the projection balances them.
    ScopedStage s(timers_, "project");
    applyInflow();
    pressureIterations_ = projection_.project(velocity_, dt, params_.fluidDensity).iterations;
    maxDivergence_ = measureDivergence();
  }
  {
    ScopedStage s(timers_, "advect scalars");
    for (Grid<float, D>* f : {&density_, &temperature_}) {
      extendIntoSolid(*f);
      advector_.advect(*f, velocity_, dt);
    }
    for (auto& sc : scalars_) {
      extendIntoSolid(sc.field);
      advector_.advect(sc.field, velocity_, dt);
    }
    dissipate(dt);
  }
  ++steps_;
  if (params_.checkFinite) checkFinite();
}

template <int D>
void SmokeSolver<D>::applyScalarSources(double dt) {
  for (const auto& src : sources_) {
    const bool set = src.mode == SmokeSource<D>::Mode::Set;
    parallelFor(0, src.cells.size(), [&](std::size_t k) {
      const auto [cell, w] = src.cells[k];
      if (set) {
        density_[cell] += static_cast<float>(w * (src.density - density_[cell]));
        if (src.temperature > 0.0) temperature_[cell] += static_cast<float>(w * (src.temperature - temperature_[cell]));
      } else {
        density_[cell] += static_cast<float>(w * src.density * dt);
        temperature_[cell] += static_cast<float>(w * src.temperature * dt);
      }
    }, 256);
  }
}

template <int D>
void SmokeSolver<D>::extendIntoSolid(Grid<float, D>& field) const {
  parallelFor(0, borderCells_.size(), [&](std::size_t k) {
    double sum = 0.0;
    for (std::size_t j = borderStart_[k]; j < borderStart_[k + 1]; ++j) sum += field[borderNeighbours_[j]];
    field[borderCells_[k]] = static_cast<float>(sum / static_cast<double>(borderStart_[k + 1] - borderStart_[k]));
  }, 256);
}

template <int D>
void SmokeSolver<D>::applyInflow() {
  for (const auto& src : sources_) {
    if (!src.velocity) continue;
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
void SmokeSolver<D>::dissipate(double dt) {
  const float keepRho = static_cast<float>(std::exp(-params_.densityDissipation * dt));
  const float keepT = static_cast<float>(std::exp(-params_.temperatureDissipation * dt));
  const float ambient = static_cast<float>(params_.buoyancy.ambientTemperature);
  if (keepRho != 1.0f || keepT != 1.0f)
    parallelFor(0, density_.count(), [&](std::size_t i) {
      density_[i] *= keepRho;
      temperature_[i] = ambient + (temperature_[i] - ambient) * keepT;
    });
  for (auto& sc : scalars_) {
    const float keep = static_cast<float>(std::exp(-sc.dissipation * dt));
    if (keep != 1.0f) parallelFor(0, sc.field.count(), [&](std::size_t i) { sc.field[i] *= keep; });
  }
}

template <int D>
double SmokeSolver<D>::measureDivergence() {
  projection_.divergence(velocity_, divergence_);
  return parallelMax(divergence_.count(), [&](std::size_t i) { return std::abs(divergence_[i]); });
}

template <int D>
void SmokeSolver<D>::checkFinite() const {
  auto fail = [&](const std::string& field) {
    throw SimulationError("smoke solver: non-finite " + field + " at step " + std::to_string(steps_));
  };
  static const char* axisName[] = {"x", "y", "z"};
  for (int a = 0; a < D; ++a)
    if (!allFinite(velocity_.component(a).data())) fail(std::string("velocity ") + axisName[a]);
  if (!allFinite(density_.data())) fail("density");
  if (!allFinite(temperature_.data())) fail("temperature");
  for (const auto& sc : scalars_)
    if (!allFinite(sc.field.data())) fail("scalar '" + sc.name + "'");
}

template <int D>
SmokeStatistics SmokeSolver<D>::statistics() const {
  SmokeStatistics s;
  const double dV = spec_.cellVolume();
  for (int a = 0; a < D; ++a) {
    const auto& u = velocity_.component(a);
    const auto& w = projection_.faceWeights().component(a);
    s.kineticEnergy += 0.5 * params_.fluidDensity * dV * parallelSum(u.count(), [&](std::size_t i) {
      return double(w[i]) * u[i] * u[i];
    });
    s.maxSpeed = std::max(s.maxSpeed, parallelMax(u.count(), [&](std::size_t i) { return std::abs(u[i]); }));
  }
  s.totalDensity = dV * parallelSum(density_.count(), [&](std::size_t i) {
    return solid_[i] > 0.5f ? 0.0 : double(density_[i]);
  });
  s.maxDivergence = maxDivergence_;
  s.pressureIterations = pressureIterations_;
  s.viscosityIterations = viscosityIterations_;
  s.step = steps_;
  return s;
}

template class SmokeSolver<2>;
template class SmokeSolver<3>;

}  // namespace msim::fluid
