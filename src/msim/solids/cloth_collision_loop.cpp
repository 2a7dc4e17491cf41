#include "msim/solids/cloth_collision_loop.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <stdexcept>

#include "msim/core/seconds_since.hpp"
#include "msim/solids/strain_limit.hpp"

namespace msim::solids {

ClothCollisionLoop::ClothCollisionLoop(std::vector<std::array<int, 3>> triangles, std::size_t particleCount,
                                       const NewmarkSettings& newmark, const ClothCollisionSettings& settings)
    : settings_(settings),
      pairs_(std::move(triangles), particleCount),
      repulsion_(settings.repulsion),
      resolver_(settings.collision),
      stepper_(newmark) {
  if (settings.innerSteps < 1) throw std::invalid_argument("cloth collisions: the inner step count must be >= 1");
  if (!(settings.repulsion.thickness > 0.0) || !(settings.repulsion.stiffness >= 0.0))
    throw std::invalid_argument("cloth collisions: the thickness must be > 0 and the repulsion stiffness >= 0");
}

ClothCollisionStats ClothCollisionLoop::step(MassSpringSystem& system, double T, const std::function<double()>& innerLimit,
                                             const BodyContact* bodies, const std::function<void(double)>& placeBodies) {
  if (!(T > 0.0)) throw std::invalid_argument("cloth collisions: the outer step must be > 0");
  ClothCollisionStats stats;
  const std::size_t n = system.size();

  // A. Pairs within the thickness of each other somewhere between the positions and where the
  // velocities take them relative to the cloth's mean motion.
  auto clock = std::chrono::steady_clock::now();
  const Vec3 mean = system.meanVelocity();
  predicted_.resize(n);
  for (std::size_t p = 0; p < n; ++p) predicted_[p] = system.x[p] + T * (system.v[p] - mean);
  repulsion_.findPairs(pairs_, system.x, predicted_);
  stats.pointTrianglePairs = repulsion_.stats().pointTrianglePairs;
  stats.edgeEdgePairs = repulsion_.stats().edgeEdgePairs;
  start_ = system.x;
  stats.secondsPairs = secondsSince(clock);

  // B. The inner steps.
  clock = std::chrono::steady_clock::now();
  double elapsed = 0.0;
  while (T - elapsed > 1e-12 * T) {
    const double limit = innerLimit();
    if (!(limit > 0.0)) throw std::invalid_argument("cloth collisions: the stable inner step must be > 0");
    const double remaining = T - elapsed;
    const double innerDt = remaining / std::ceil(remaining / limit - 1e-9);  // the rest in equal steps within the limit
    elapsed += innerDt;
    ++stats.innerSteps;
    if (placeBodies) placeBodies(elapsed);
    const NewmarkStats s = stepper_.step(system, innerDt, bodies, &repulsion_);
    if (settings_.strainLimit > 0.0) {
      limitStrain(system, settings_.strainLimit, settings_.strainLimitSweeps, innerDt);
      if (bodies) bodies->pushOut(system.x, system.v, system.pinned);
    }
    stats.newmark.iterations += s.iterations;
    stats.newmark.preconditionerSetups += s.preconditionerSetups;
    stats.newmark.converged = stats.newmark.converged && s.converged;
    stats.newmark.contacts = s.contacts;
    stats.repulsions += s.repulsions;
  }
  stats.secondsInner = secondsSince(clock);

  // C. Collisions from the collision-free start; the corrections become velocity.
  clock = std::chrono::steady_clock::now();
  before_ = system.x;
  stats.collisions = resolver_.resolve(pairs_, start_, system.x, system.mass, system.pinned, T, T / stats.innerSteps,
                                       settings_.repulsion, bodies);
  for (std::size_t p = 0; p < n; ++p)
    if (!system.pinned[p]) system.v[p] += (system.x[p] - before_[p]) / T;
  stats.secondsCollisions = secondsSince(clock);
  return stats;
}

}  // namespace msim::solids
