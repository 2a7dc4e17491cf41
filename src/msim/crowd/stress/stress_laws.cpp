#include "msim/crowd/stress/stress_laws.hpp"

#include <algorithm>
#include <cmath>

namespace msim::crowd::stress {

namespace {

double middleBranch(double density, const StressLaws& l) {
  return l.c1 * density / std::sqrt(l.yield - density + l.epsilon) - l.c2;
}

}  // namespace

double discomfort(double density, const StressLaws& l) {
  if (density < l.critical) return l.continuousLowerBranch ? middleBranch(l.critical, l) : 0.0;
  if (density < l.yield) return middleBranch(density, l);
  return l.c1 / std::sqrt(l.epsilon) * density - l.c2;
}

double discomfortSlope(double density, const StressLaws& l) {
  if (density < l.critical) return 0.0;
  if (density < l.yield) {
    // d/drho of c1 rho (y - rho + e)^(-1/2) = c1 (y - rho + e)^(-1/2) + c1 rho / 2 (y - rho + e)^(-3/2)
    const double gap = l.yield - density + l.epsilon;
    return l.c1 / std::sqrt(gap) + 0.5 * l.c1 * density / (gap * std::sqrt(gap));
  }
  return l.c1 / std::sqrt(l.epsilon);
}

double frictionCoefficient(double density, const StressLaws& l) {
  if (density <= l.critical) return 0.0;
  if (density >= l.yield) return l.frictionMax;
  return l.frictionMax * (density - l.critical) / (l.yield - l.critical);
}

double frictionBound(double density, const StressLaws& l) {
  return 0.5 * std::sqrt(3.0) * frictionCoefficient(density, l) * std::max(0.0, discomfort(density, l));
}

Vec2 clampAcceleration(const Vec2& acceleration, double maxAcceleration) {
  const double norm = acceleration.norm();
  return norm > maxAcceleration ? Vec2(acceleration * (maxAcceleration / norm)) : acceleration;
}

}  // namespace msim::crowd::stress
