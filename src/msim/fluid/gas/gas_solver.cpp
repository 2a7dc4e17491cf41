#include "msim/fluid/gas/gas_solver.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/parallel.hpp"

namespace msim::fluid {

namespace {

template <int D>
Vec3 toVec3(const Vec<D>& x) {
  Vec3 p = Vec3::Zero();
  for (int a = 0; a < D; ++a) p[a] = x[a];
  return p;
}

}  // namespace

template <int D>
GasSolver<D>::GasSolver(const GridSpec<D>& spec, const GasParams& params, const MotionField& field,
                        const numerics::TransportBoundaries<D>& boundaries)
    : spec_(spec),
      params_(params),
      density_(spec, 0.0f),
      temperature_(spec, static_cast<float>(params.ambientTemperature)),
      transport_(spec, boundaries),
      steadyVelocity_(spec),
      windyVelocity_(spec) {
  // The motion field sampled on the cell faces, once: it is steady. 2D scenes live in the z = 0
  // plane of the 3D field.
  for (int a = 0; a < D; ++a) {
    auto& u = steadyVelocity_.component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      u[lin] = static_cast<float>(field.velocity(toVec3<D>(u.position(f)))[a]);
    });
  }
  transport_.setVelocity(steadyVelocity_);
}

template <int D>
void GasSolver<D>::addWind(turbulence::TurbulentWind<D> wind) {
  winds_.push_back(std::move(wind));
  refreshVelocity();
}

template <int D>
void GasSolver<D>::setTime(double time) {
  time_ = time;
  if (!winds_.empty()) refreshVelocity();
}

template <int D>
void GasSolver<D>::refreshVelocity() {
  windyVelocity_ = steadyVelocity_;  // copied into the same storage every step
  for (int a = 0; a < D; ++a) {
    auto& u = windyVelocity_.component(a);
    for (const auto& w : winds_) w.forEachSample(u, a, time_, [&](std::size_t lin, float v) { u[lin] += v; });
  }
  transport_.setVelocity(windyVelocity_);
}

template <int D>
void GasSolver<D>::setSolid(const Grid<float, D>& solid) {
  transport_.setSolid(solid);
  parallelFor(0, density_.count(), [&](std::size_t i) {
    if (solid[i] > 0.5f) density_[i] = 0.0f;
  });
}

template <int D>
double GasSolver<D>::stableTimestep() const {
  return params_.cfl * transport_.maxStableDt(std::max(params_.densityDiffusion, params_.temperatureDiffusion));
}

template <int D>
void GasSolver<D>::emit(double dt) {
  const auto& solid = transport_.solid();
  for (const GasSource& s : sources_) {
    for (const auto& [cell, coverage] : s.cells) {
      if (solid[cell] > 0.5f) continue;
      const double added = s.densityRate * coverage * dt;
      const double before = density_[cell];
      const double after = before + added;
      if (after > 0.0)  // mass-weighted mixing of the emitted gas's temperature
        temperature_[cell] = static_cast<float>((before * temperature_[cell] + added * s.temperature) / after);
      density_[cell] = static_cast<float>(after);
    }
  }
}

template <int D>
void GasSolver<D>::decay(double dt) {
  const float densityFactor = static_cast<float>(std::exp(-params_.densityDissipation * dt));
  const float coolingFactor = static_cast<float>(std::exp(-params_.cooling * dt));
  const float ambient = static_cast<float>(params_.ambientTemperature);
  if (densityFactor == 1.0f && coolingFactor == 1.0f) return;
  parallelFor(0, density_.count(), [&](std::size_t i) {
    density_[i] *= densityFactor;
    temperature_[i] = ambient + (temperature_[i] - ambient) * coolingFactor;
  });
}

template <int D>
void GasSolver<D>::step(double dt) {
  {
    ScopedStage s(timers_, "emit");
    emit(dt);
  }
  {
    ScopedStage s(timers_, "transport density");
    numerics::TransportSettings densitySettings;
    densitySettings.form = numerics::TransportForm::Conservative;
    densitySettings.diffusivity = params_.densityDiffusion;
    transport_.step(density_, densitySettings, dt);
  }
  {
    ScopedStage s(timers_, "transport temperature");
    numerics::TransportSettings temperatureSettings;
    temperatureSettings.form = numerics::TransportForm::Advective;
    temperatureSettings.diffusivity = params_.temperatureDiffusion;
    temperatureSettings.inflowValue = params_.ambientTemperature;
    transport_.step(temperature_, temperatureSettings, dt);
  }
  {
    // Exact integration of the linear loss terms over the step (no stability limit of their own).
    ScopedStage s(timers_, "decay");
    decay(dt);
  }
  time_ += dt;
  if (!winds_.empty()) {
    // The next step's flow, so that stableTimestep() sees it.
    ScopedStage s(timers_, "winds");
    refreshVelocity();
  }
}

template <int D>
GasStatistics GasSolver<D>::statistics() const {
  GasStatistics s;
  const double cellVolume = spec_.cellVolume();
  double mass = 0.0, weightedT = 0.0;
  Vec3 moment = Vec3::Zero();
  for (std::size_t i = 0; i < density_.count(); ++i) {
    const double rho = density_[i], T = temperature_[i];
    if (!std::isfinite(rho) || !std::isfinite(T)) {
      s.finite = false;
      continue;
    }
    mass += rho;
    weightedT += rho * T;
    s.maxDensity = std::max(s.maxDensity, rho);
    s.maxTemperature = std::max(s.maxTemperature, T);
    if (rho != 0.0) moment += rho * toVec3<D>(density_.position(density_.coord(i)));
  }
  s.mass = mass * cellVolume;
  s.meanTemperature = mass > 0.0 ? weightedT / mass : params_.ambientTemperature;
  s.centroid = mass > 0.0 ? Vec3(moment / mass) : Vec3::Zero();
  return s;
}

template class GasSolver<2>;
template class GasSolver<3>;

}  // namespace msim::fluid
