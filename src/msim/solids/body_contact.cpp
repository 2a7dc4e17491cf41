#include "msim/solids/body_contact.hpp"

#include <algorithm>
#include <cmath>

namespace msim::solids {

Vec3 BodyContact::normal(std::size_t b, const Vec3& x) const {
  // Central differences of the distance over a small step (bodies are any Shape).
  constexpr double kStep = 1e-6;
  Vec3 n;
  for (int a = 0; a < 3; ++a) {
    Vec3 lo = x, hi = x;
    lo[a] -= kStep;
    hi[a] += kStep;
    n[a] = distance(b, hi) - distance(b, lo);
  }
  const double length = n.norm();
  return length > 0.0 ? Vec3(n / length) : Vec3(Vec3::UnitY());
}

Vec3 BodyContact::gamma(std::size_t b, const Vec3& x, const Vec3& v) const {
  const ContactBody& body = bodies_[b];
  const Vec3 n = normal(b, x);
  const Vec3 bodyV = body.velocityAt(x);
  const double vN = v.dot(n), bodyN = bodyV.dot(n);
  const double starN = std::max(vN, bodyN);
  const Vec3 bodyT = bodyV - bodyN * n;
  const Vec3 relT = (v - vN * n) - bodyT;
  const double slip = relT.norm();
  const double keep = slip > 0.0 ? std::max(0.0, 1.0 - body.friction * (starN - vN) / slip) : 0.0;
  return starN * n + bodyT + keep * relT;
}

Vec3 BodyContact::move(const Vec3& x, const Vec3& v, double dt, int& body) const {
  const Vec3 end = x + dt * v;
  body = -1;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const double after = distance(b, end);
    if (!(after < 0.0)) continue;
    body = static_cast<int>(b);
    const Vec3 n = normal(b, end);
    if (method_ == ContactMethod::Projection) return end - after * n;
    const double before = std::max(0.0, distance(b, x) + dt * bodies_[b].velocityAt(end).dot(n));
    const double theta = before / (before - after);
    const Vec3 meet = x + theta * dt * v;
    return meet + (1.0 - theta) * dt * gamma(b, meet, v);
  }
  return end;
}

int BodyContact::pushOut(Vec3& x) const {
  int inside = -1;
  for (std::size_t b = 0; b < bodies_.size(); ++b) {
    const double depth = distance(b, x);
    if (!(depth < 0.0)) continue;
    x -= depth * normal(b, x);
    inside = static_cast<int>(b);
  }
  return inside;
}

int BodyContact::pushOut(std::vector<Vec3>& x, std::vector<Vec3>& v, const std::vector<char>& pinned) const {
  int moved = 0;
  for (std::size_t p = 0; p < x.size(); ++p) {
    if (pinned[p]) continue;
    const int body = pushOut(x[p]);
    if (body < 0) continue;
    v[p] = gamma(static_cast<std::size_t>(body), x[p], v[p]);
    ++moved;
  }
  return moved;
}

}  // namespace msim::solids
