#include "msim/crowd/lookahead/continuum_lookahead.hpp"

#include <algorithm>
#include <cmath>

namespace msim::crowd::lookahead {

double continuumSpeed(double density, double freeSpeed, const ContinuumSettings& settings) {
  return std::max(settings.slowest, freeSpeed * std::max(0.0, 1.0 - density / settings.maxDensity));
}

double continuumSpeedSlope(double density, double freeSpeed, const ContinuumSettings& settings) {
  // Zero where f is floored: denser still does not slow it further.
  if (continuumSpeed(density, freeSpeed, settings) <= settings.slowest) return 0.0;
  return -freeSpeed / settings.maxDensity;
}

DirectionChoice bestDirection(const Vec2& preferred, const Vec2& densityGradient, double speedSlope, const Vec2& start,
                              const ContinuumSettings& settings) {
  DirectionChoice out;
  const double speed = preferred.norm();
  if (!(speed > 0.0)) {
    out.converged = true;
    return out;
  }
  // J(v) = p.v + k (v.g)(p.v), k = f' T / 2. Its Hessian k (g p^T + p g^T) has the eigenvalues
  // k (g.p +- |g||p|), one of either sign, so J has no interior maximum on the disc: the maximum
  // lies on the unit circle, and the ascent runs along it. With v = (cos t, sin t) and v' its
  // quarter turn, dJ/dt = p.v' + k (v'.g)(p.v) + k (v.g)(p.v') and
  // d2J/dt2 = -p.v + 2 k ((v'.g)(p.v') - (v.g)(p.v)): a Newton step in t where J is concave there,
  // else a step towards larger J, each at most a radian's tangent, taken as v + step v' normalised
  // (a turn by atan(step): the same fixed point, without trigonometry).
  const double k = 0.5 * speedSlope * settings.planHorizon;
  const Vec2& p = preferred;
  const Vec2& g = densityGradient;
  // Without a density change along the way (empty or uniform surroundings, or a speed the
  // density does not change) J = p.v, maximal along p: most far levels of a sparse crowd.
  if (k == 0.0 || g.squaredNorm() == 0.0) {
    out.direction = preferred / speed;
    out.converged = true;
    return out;
  }
  Vec2 v = start.squaredNorm() > 0.0 ? Vec2(start.normalized()) : Vec2(preferred / speed);
  for (int it = 0; it < settings.maxIterations; ++it) {
    const Vec2 turned(-v.y(), v.x());
    const double pv = p.dot(v), pt = p.dot(turned), gv = g.dot(v), gt = g.dot(turned);
    const double first = pt + k * (gt * pv + gv * pt);
    const double second = -pv + 2.0 * k * (gt * pt - gv * pv);
    const double step = std::clamp(second < 0.0 ? -first / second : std::copysign(1.0, first), -1.0, 1.0);
    v = (v + step * turned).normalized();
    out.iterations = it + 1;
    if (std::abs(step) < settings.tolerance) {
      out.converged = true;
      break;
    }
  }
  out.direction = v;
  return out;
}

CascadeResult continuumLookahead(const FutureDensity& future, const ContinuumSettings& settings, const Vec2f& x,
                                 const Vec2f& v, const Vec2f& preferred, double freeSpeed, int depth, int lowest) {
  CascadeResult out;
  const double preferredSpeed = preferred.norm();
  if (!(preferredSpeed > 0.0)) return out;
  Vec2 wanted = preferred.cast<double>();
  const Vec2 current = v.cast<double>();
  DirectionChoice choice;
  double density = 0.0;
  for (int level = std::min(depth, future.levels()); level >= lowest; --level) {
    // Where the agent will be dt_i ahead; it was splatted there itself.
    const Vec2 at = future.predicted(level, x, v);
    const FutureDensity::Density d = future.othersDensity(level, at);
    density = d.value;
    choice = bestDirection(wanted, d.gradient, continuumSpeedSlope(density, freeSpeed, settings), current, settings);
    out.iterations += choice.iterations;
    ++out.solves;
    wanted = preferredSpeed * choice.direction;
  }
  if (out.solves == 0) {
    out.velocity = preferred.cast<double>();
    return out;
  }
  out.velocity = lowest == 0 ? Vec2(continuumSpeed(density, freeSpeed, settings) * choice.direction) : wanted;
  return out;
}

}  // namespace msim::crowd::lookahead
