#include "msim/crowd/stress/stress_dynamics.hpp"

#include <algorithm>
#include <stdexcept>

#include "msim/core/interpolation.hpp"
#include "msim/core/parallel.hpp"

namespace msim::crowd::stress {

namespace {

// Below this density (per m^2) a face or an agent has nobody to push: no stress acceleration.
constexpr double kEmpty = 0.05;

}  // namespace

StressDynamics::StressDynamics(const GridSpec<2>& grid, const StressSettings& settings)
    : settings_(settings), grid_(grid), discomfortGradient_(grid), friction_(grid) {
  if (!(settings.relaxation > 0.0) || !(settings.maxAcceleration > 0.0))
    throw std::invalid_argument("crowd stress: the relaxation time and the largest acceleration must be > 0");
}

void StressDynamics::accelerate(std::span<const Vec2f> x, std::span<const Vec2f> v, std::span<const Vec2f> collisionFree,
                                const Grid<float, 2>& free, double dt, StressStepStats& stats) {
  grid_.splat(x, v, free, collisionFree);
  grid_.discomfortGradient(settings_.laws, discomfortGradient_);
  const GridSpec<2>& spec = grid_.grid();
  const int nx = spec.res.x(), ny = spec.res.y();
  const double tau = settings_.relaxation;
  const Grid<float, 2>& rho = grid_.density();
  // m* on the faces: each face's density, velocity and collision-free velocity the mean of its two cells'.
  momentum_.setZero(static_cast<Eigen::Index>(grid_.faceCount()));
  const auto faceMomentum = [&](const IVec<2>& a, const IVec<2>& b, int axis, float gradient) {
    const double density = 0.5 * (rho(a) + rho(b));
    if (density < kEmpty) return 0.0;
    const Grid<float, 2>& vel = axis == 0 ? grid_.velocityX() : grid_.velocityY();
    const Grid<float, 2>& cf = axis == 0 ? grid_.collisionFreeX() : grid_.collisionFreeY();
    const double velocity = 0.5 * (vel(a) + vel(b)), wanted = 0.5 * (cf(a) + cf(b));
    return density * (velocity + dt * ((wanted - velocity) / tau - gradient / density));
  };
  const std::size_t xFaces = static_cast<std::size_t>((nx + 1) * ny);
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      const std::size_t f = static_cast<std::size_t>(i + (nx + 1) * j);
      if (grid_.activeFace(f))
        momentum_[static_cast<Eigen::Index>(f)] =
            faceMomentum(IVec<2>(i - 1, j), IVec<2>(i, j), 0, discomfortGradient_.component(0)(IVec<2>(i, j)));
    }
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const std::size_t f = xFaces + static_cast<std::size_t>(i + nx * j);
      if (grid_.activeFace(f))
        momentum_[static_cast<Eigen::Index>(f)] =
            faceMomentum(IVec<2>(i, j - 1), IVec<2>(i, j), 1, discomfortGradient_.component(1)(IVec<2>(i, j)));
    }
  const FrictionResult r = grid_.friction(momentum_, dt, settings_.laws, settings_.qp, change_);
  ++stats.solves;
  stats.iterations += r.qp.iterations;
  stats.unconverged += r.qp.converged ? 0 : 1;
  stats.dissipated += r.energyBefore - r.energyAfter;
  // Friction's acceleration on the faces, dt D s* / (dt rho).
  friction_.fill(0.0f);
  for (int j = 0; j < ny; ++j)
    for (int i = 1; i < nx; ++i) {
      const double density = 0.5 * (rho(IVec<2>(i - 1, j)) + rho(IVec<2>(i, j)));
      const auto f = static_cast<Eigen::Index>(i + (nx + 1) * j);
      if (density >= kEmpty) friction_.component(0)(IVec<2>(i, j)) = static_cast<float>(change_[f] / (dt * density));
    }
  for (int j = 1; j < ny; ++j)
    for (int i = 0; i < nx; ++i) {
      const double density = 0.5 * (rho(IVec<2>(i, j - 1)) + rho(IVec<2>(i, j)));
      const auto f = static_cast<Eigen::Index>(xFaces + static_cast<std::size_t>(i + nx * j));
      if (density >= kEmpty) friction_.component(1)(IVec<2>(i, j)) = static_cast<float>(change_[f] / (dt * density));
    }
  // Each agent's acceleration (eq. 4.6), clamped (eq. 4.7).
  acceleration_.resize(x.size());
  parallelFor(0, x.size(), [&](std::size_t k) {
    const Vec2 at = x[k].cast<double>();
    const double density = std::max<double>(sampleLinear<2>(rho, at), kEmpty);
    const Vec2 a = (collisionFree[k] - v[k]).cast<double>() / tau - sampleLinear<2>(discomfortGradient_, at) / density +
                   sampleLinear<2>(friction_, at);
    acceleration_[k] = clampAcceleration(a, settings_.maxAcceleration).cast<float>();
  });
}

StressStepStats StressDynamics::step(std::span<Vec2f> x, std::span<Vec2f> v, std::span<const Vec2f> collisionFree,
                                     const Grid<float, 2>& free, double dt) {
  if (x.size() != v.size() || x.size() != collisionFree.size())
    throw std::invalid_argument("crowd stress: one position, velocity and collision-free velocity per agent expected");
  if (!(dt > 0.0)) throw std::invalid_argument("crowd stress: the step must be > 0");
  StressStepStats stats;
  const float h = static_cast<float>(dt);
  // The midpoint: V(1/2) = V + dt/2 a(X, V), X(1/2) = X + dt/2 V; then V += dt a(X(1/2), V(1/2)),
  // X += dt V(1/2).
  accelerate(x, v, collisionFree, free, dt, stats);
  halfX_.resize(x.size());
  halfV_.resize(x.size());
  for (std::size_t k = 0; k < x.size(); ++k) {
    halfV_[k] = v[k] + 0.5f * h * acceleration_[k];
    halfX_[k] = x[k] + 0.5f * h * v[k];
  }
  accelerate(halfX_, halfV_, collisionFree, free, dt, stats);
  for (std::size_t k = 0; k < x.size(); ++k) {
    v[k] += h * acceleration_[k];
    x[k] += h * halfV_[k];
  }
  return stats;
}

}  // namespace msim::crowd::stress
