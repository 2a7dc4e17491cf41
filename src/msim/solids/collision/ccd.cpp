#include "msim/solids/collision/ccd.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Geometry>

#include "msim/solids/collision/proximity.hpp"

namespace msim::solids {

namespace {

using Points = std::array<Vec3, 4>;

// Relative to a polynomial's scale (L^3 for the coplanarity cubic, L^2 for the in-plane
// quadratics, L the largest relative distance between the points involved over the step): a
// polynomial whose coefficients are all below this is zero to within the rounding of its
// coefficients (a few tens of ulps of the scale), and a value below it touches zero. For the cubic
// both mean the four points are coplanar to about 1e-13 L.
constexpr double kCoplanarTolerance = 1e-13;
// Newton's iteration stops when its step falls below this (t is in [0, 1]).
constexpr double kTimeTolerance = 1e-15;
// With S the largest coordinate of the points over the step (positions at a time t are rounded to
// ulps of S): distances that differ by less than kDistanceRounding S are equal to rounding, and a
// candidate time counts as a contact while the proximity is within eps + kDistanceRelaxation S,
// so that a root refined in floating point is not rejected for the last bits of its position.
constexpr double kDistanceRounding = 1e-12;
constexpr double kDistanceRelaxation = 1e-10;
// How far ahead (a fraction of the step) a pair that starts within eps is asked whether it is
// still closing in at a candidate time.
constexpr double kLookAhead = 1e-4;

// A polynomial of degree at most 3 in t (the in-plane quadratics have c3 = 0).
struct Cubic {
  double c0 = 0.0, c1 = 0.0, c2 = 0.0, c3 = 0.0;
  double operator()(double t) const { return ((c3 * t + c2) * t + c1) * t + c0; }
  double derivative(double t) const { return (3.0 * c3 * t + 2.0 * c2) * t + c1; }
  double largestCoefficient() const { return std::max({std::abs(c0), std::abs(c1), std::abs(c2), std::abs(c3)}); }
};

Points positionsAt(const Points& x0, const Points& x1, double t) {
  if (t == 1.0) return x1;
  Points x;
  for (std::size_t i = 0; i < 4; ++i) x[i] = x0[i] + t * (x1[i] - x0[i]);
  return x;
}

// f(t) = (A + t dA) x (B + t dB) . (C + t dC) with A, B, C the points relative to x_0 at the start
// and dA, dB, dC their changes over the step (taken from the displacements, which are more accurate
// than differences of the end positions when the motion is small). `bound` gets L^3 >= |f| on [0, 1].
Cubic coplanarityCubic(const Points& x0, const Points& x1, double& bound) {
  const Vec3 d0 = x1[0] - x0[0];
  const Vec3 a = x0[1] - x0[0], b = x0[2] - x0[0], c = x0[3] - x0[0];
  const Vec3 da = (x1[1] - x0[1]) - d0, db = (x1[2] - x0[2]) - d0, dc = (x1[3] - x0[3]) - d0;
  const double largest = std::max({a.norm(), b.norm(), c.norm(), (a + da).norm(), (b + db).norm(), (c + dc).norm()});
  bound = largest * largest * largest;
  Cubic f;
  f.c0 = a.cross(b).dot(c);
  f.c1 = da.cross(b).dot(c) + a.cross(db).dot(c) + a.cross(b).dot(dc);
  f.c2 = da.cross(db).dot(c) + da.cross(b).dot(dc) + a.cross(db).dot(dc);
  f.c3 = da.cross(db).dot(dc);
  return f;
}

// The roots of a t^2 + b t + c in (0, 1), increasing, by the formula without cancellation (a
// vanishing a leaves the other root finite; a root beyond the step is dropped).
int quadraticRootsInStep(double a, double b, double c, std::array<double, 2>& roots) {
  int count = 0;
  const auto keep = [&](double t) {
    if (t > 0.0 && t < 1.0) roots[static_cast<std::size_t>(count++)] = t;
  };
  if (a == 0.0) {
    if (b != 0.0) keep(-c / b);
    return count;
  }
  const double discriminant = b * b - 4.0 * a * c;
  if (discriminant < 0.0) return 0;
  const double q = -0.5 * (b + std::copysign(std::sqrt(discriminant), b));
  keep(q / a);
  if (q != 0.0) keep(c / q);
  if (count == 2 && roots[0] > roots[1]) std::swap(roots[0], roots[1]);
  return count;
}

// The root of f in (lo, hi), where f is monotone and f(lo), f(hi) have strictly opposite signs:
// Newton's method, falling back to bisection whenever a step leaves the bracket or fails to halve
// the previous step, so it converges even where f' is small.
double rootInBracket(const Cubic& f, double lo, double hi) {
  const bool increasing = f(lo) < 0.0;
  double t = 0.5 * (lo + hi), step = hi - lo;
  for (int iteration = 0; iteration < 100; ++iteration) {
    const double value = f(t);
    if (value == 0.0) return t;
    ((value < 0.0) == increasing ? lo : hi) = t;
    const double newton = value / f.derivative(t), previousStep = step;
    if (t - newton > lo && t - newton < hi && std::abs(newton) < 0.5 * std::abs(previousStep)) {
      step = newton;
    } else {
      step = t - 0.5 * (lo + hi);
    }
    t -= step;
    if (std::abs(step) <= kTimeTolerance) return t;
  }
  return t;
}

// Visits the candidate roots of f in [0, 1] in increasing order and returns the first that
// `accept` takes: t = 0 when |f(0)| <= zero; each sign change, bracketed between f's critical
// points (where f is monotone) and refined; each critical point where |f| <= zero (a double root,
// or an extremum grazing zero within rounding); t = 1 when |f(1)| <= zero.
template <class Accept>
std::optional<double> firstAcceptedRoot(const Cubic& f, double zero, const Accept& accept) {
  double left = 0.0, fLeft = f(0.0);
  if (std::abs(fLeft) <= zero && accept(0.0)) return 0.0;
  std::array<double, 2> critical{};
  const int criticalCount = quadraticRootsInStep(3.0 * f.c3, 2.0 * f.c2, f.c1, critical);
  for (int k = 0; k <= criticalCount; ++k) {
    const double right = k < criticalCount ? critical[static_cast<std::size_t>(k)] : 1.0;
    const double fRight = f(right);
    if ((fLeft < 0.0 && fRight > 0.0) || (fLeft > 0.0 && fRight < 0.0)) {
      const double root = rootInBracket(f, left, right);
      if (accept(root)) return root;
    }
    if (std::abs(fRight) <= zero && accept(right)) return right;
    left = right;
    fLeft = fRight;
  }
  return std::nullopt;
}

using DistanceFunction = double (*)(const Points&);

// Whether a candidate time is reported (see the header): the proximity at t is within eps (relaxed
// by rounding), and the pair either started farther than eps apart, or crosses into the other
// primitive at t (in-plane, decided by the caller), or is closer at t than at the start, or is still
// closing in just after t. A pair that starts within eps and keeps or increases its distance (rigid,
// parallel or separating motion) is not a collision.
class ContactRule {
 public:
  ContactRule(const Points& x0, const Points& x1, double eps, DistanceFunction distance)
      : x0_(x0), x1_(x1), eps_(eps), distance_(distance) {
    double scale = 0.0;
    for (std::size_t i = 0; i < 4; ++i)
      scale = std::max({scale, x0[i].cwiseAbs().maxCoeff(), x1[i].cwiseAbs().maxCoeff()});
    noise_ = kDistanceRounding * scale;
    within_ = eps + kDistanceRelaxation * scale;
  }

  double distanceAt(double t) const { return distance_(positionsAt(x0_, x1_, t)); }

  bool accepts(double t, bool crossingInto) const {
    const double d = distanceAt(t);
    if (!(d <= within_)) return false;
    if (crossingInto) return true;
    if (!start_) start_ = distanceAt(0.0);  // only asked for when there is a candidate
    if (*start_ > eps_ || d < *start_ - noise_) return true;
    return t < 1.0 && distanceAt(std::min(1.0, t + kLookAhead)) < d - noise_;
  }

 private:
  const Points& x0_;
  const Points& x1_;
  double eps_;
  DistanceFunction distance_;
  double noise_ = 0.0, within_ = 0.0;
  mutable std::optional<double> start_;  // the distance at t = 0
};

double cross2(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// The coordinate to drop when projecting the (common) plane of the four points onto two axes: that
// of the largest component of the largest normal among the configurations at t = 0, 1/2 and 1, or,
// when all four points stay collinear, the smallest component of their line's direction.
int droppedAxis(const Points& x0, const Points& x1) {
  Vec3 normal = Vec3::Zero(), line = Vec3::Zero();
  for (const double t : {0.0, 0.5, 1.0}) {
    const Points x = positionsAt(x0, x1, t);
    const Vec3 a = x[1] - x[0], b = x[2] - x[0], c = x[3] - x[0];
    for (const Vec3& n : {a.cross(b), a.cross(c), b.cross(c)})
      if (n.squaredNorm() > normal.squaredNorm()) normal = n;
    for (std::size_t i = 0; i < 4; ++i)
      for (std::size_t j = i + 1; j < 4; ++j)
        if ((x[j] - x[i]).squaredNorm() > line.squaredNorm()) line = x[j] - x[i];
  }
  Eigen::Index axis = 1;
  if (normal.norm() > kCoplanarTolerance * line.squaredNorm()) {
    normal.cwiseAbs().maxCoeff(&axis);
  } else if (line.squaredNorm() > 0.0) {
    line.cwiseAbs().minCoeff(&axis);
  }
  return static_cast<int>(axis);
}

// A vertex v against a segment (a, b) in the projected plane, each point moving linearly; `other`
// is the triangle's third vertex (point-triangle) or v's partner on its edge (edge-edge).
struct VertexSegment {
  std::size_t v, a, b, other;
  bool interiorOnOthersSide;  // crossing into the triangle is towards `other`; into the edge, away from it
};

// The first accepted time at which the vertex crosses the segment's line within eps of the
// segment; when it moves along that line all step, the first at which it passes an end of the
// segment.
std::optional<double> firstVertexSegmentContact(const std::array<Vec2, 4>& p, const std::array<Vec2, 4>& d,
                                                const VertexSegment& s, const ContactRule& rule) {
  const Vec2 u0 = p[s.b] - p[s.a], du = d[s.b] - d[s.a];  // b - a
  const Vec2 w0 = p[s.v] - p[s.a], dw = d[s.v] - d[s.a];  // v - a
  const Vec2 o0 = p[s.other] - p[s.a], dO = d[s.other] - d[s.a];
  const double largest = std::max({u0.norm(), (u0 + du).norm(), w0.norm(), (w0 + dw).norm()});
  const double zero = kCoplanarTolerance * largest * largest;
  // The orientation (b - a) x (v - a): zero when v is on the segment's line.
  Cubic g;
  g.c0 = cross2(u0, w0);
  g.c1 = cross2(u0, dw) + cross2(du, w0);
  g.c2 = cross2(du, dw);
  if (g.largestCoefficient() > zero) {
    return firstAcceptedRoot(g, zero, [&](double t) {
      const double rate = g.derivative(t), side = cross2(u0 + t * du, o0 + t * dO);
      const bool into = std::abs(rate) > zero && std::abs(side) > zero && ((rate > 0.0) == (side > 0.0)) == s.interiorOnOthersSide;
      return rule.accepts(t, into);
    });
  }
  // v slides along the line: (v - a).(b - a) and (v - b).(a - b) vanish as it passes a and b.
  std::optional<double> first;
  const Vec2 z0 = u0 - w0, dz = du - dw;  // b - v
  for (const auto& [e0, de] : {std::pair{w0, dw}, std::pair{z0, dz}}) {
    Cubic h;
    h.c0 = e0.dot(u0);
    h.c1 = e0.dot(du) + de.dot(u0);
    h.c2 = de.dot(du);
    if (h.largestCoefficient() <= zero) continue;
    const auto t = firstAcceptedRoot(h, zero, [&](double t) { return rule.accepts(t, h.derivative(t) > zero); });
    if (t && (!first || *t < *first)) first = t;
  }
  return first;
}

// The primitives stay coplanar all step: the first contact in their plane (see the header).
std::optional<double> firstInPlaneContact(const Points& x0, const Points& x1, bool pointTriangle,
                                          const ContactRule& rule) {
  const int dropped = droppedAxis(x0, x1);
  const int i = dropped == 0 ? 1 : 0, j = dropped == 2 ? 1 : 2;
  std::array<Vec2, 4> p, d;
  for (std::size_t k = 0; k < 4; ++k) {
    p[k] = Vec2(x0[k][i], x0[k][j]);
    d[k] = Vec2(x1[k][i] - x0[k][i], x1[k][j] - x0[k][j]);
  }
  static constexpr std::array<VertexSegment, 3> kPointTriangle = {
      {{0, 1, 2, 3, true}, {0, 2, 3, 1, true}, {0, 3, 1, 2, true}}};
  static constexpr std::array<VertexSegment, 4> kEdgeEdge = {
      {{0, 2, 3, 1, false}, {1, 2, 3, 0, false}, {2, 0, 1, 3, false}, {3, 0, 1, 2, false}}};
  std::optional<double> first;
  const auto consider = [&](const VertexSegment& s) {
    const auto t = firstVertexSegmentContact(p, d, s, rule);
    if (t && (!first || *t < *first)) first = t;
  };
  if (pointTriangle) {
    for (const VertexSegment& s : kPointTriangle) consider(s);
  } else {
    for (const VertexSegment& s : kEdgeEdge) consider(s);
  }
  return first;
}

// The first time in [0, 1] at which the four points are coplanar and the contact rule reports the
// pair; see the header.
std::optional<double> firstCollisionTime(const Points& x0, const Points& x1, double eps, bool pointTriangle,
                                         DistanceFunction distance) {
  const ContactRule rule(x0, x1, eps, distance);
  double bound = 0.0;
  const Cubic f = coplanarityCubic(x0, x1, bound);
  const double zero = kCoplanarTolerance * bound;
  if (f.largestCoefficient() <= zero) return firstInPlaneContact(x0, x1, pointTriangle, rule);
  return firstAcceptedRoot(f, zero, [&](double t) { return rule.accepts(t, false); });
}

double pointTriangleDistance(const Points& x) { return pointTriangleProximity(x[0], x[1], x[2], x[3]).distance; }
double edgeEdgeDistance(const Points& x) { return edgeEdgeProximity(x[0], x[1], x[2], x[3]).distance; }

}  // namespace

std::optional<double> pointTriangleCollisionTime(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                                 double eps) {
  return firstCollisionTime(x0, x1, eps, true, pointTriangleDistance);
}

std::optional<double> edgeEdgeCollisionTime(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double eps) {
  return firstCollisionTime(x0, x1, eps, false, edgeEdgeDistance);
}

}  // namespace msim::solids
