#include "msim/solids/collision/proximity.hpp"

#include <algorithm>
#include <cfloat>
#include <cmath>

#include <Eigen/Geometry>

namespace msim::solids {

namespace {

// The parameter in [0, 1] of the point of segment a + t (b - a) closest to p (0 for a zero-length
// segment, whose every parameter names the same point).
double closestSegmentParameter(const Vec3& p, const Vec3& a, const Vec3& b) {
  const Vec3 ab = b - a;
  const double lengthSquared = ab.squaredNorm();
  if (!(lengthSquared > 0.0)) return 0.0;
  return std::clamp((p - a).dot(ab) / lengthSquared, 0.0, 1.0);
}

// Below this distance the direction between the closest points is rounding noise: the points are
// known only to a few ulps of the largest coordinate.
double touchingDistance(double largestCoordinate) { return 16.0 * DBL_EPSILON * largestCoordinate; }

// The unit normal of touching primitives: `cross` (the triangle's normal, or the edges' common
// normal) when it exists, else any unit vector perpendicular to `along` (a degenerate triangle's or
// parallel edges' direction), else, every point coinciding, the z axis: the caller needs a unit
// vector to push along and no direction is better than another.
Vec3 touchingNormal(const Vec3& cross, const Vec3& along) {
  if (cross.squaredNorm() > 0.0) return cross.normalized();
  if (along.squaredNorm() > 0.0) return along.unitOrthogonal();
  return Vec3::UnitZ();
}

double largestCoordinate(const Vec3& a, const Vec3& b, const Vec3& c, const Vec3& d) {
  return std::max({a.cwiseAbs().maxCoeff(), b.cwiseAbs().maxCoeff(), c.cwiseAbs().maxCoeff(),
                   d.cwiseAbs().maxCoeff()});
}

}  // namespace

std::optional<Vec3> faceProjectionWeights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  // The sub-triangle areas measured along n. A nearly degenerate triangle has ill-conditioned
  // weights; pointTriangleProximity compares them with the edges' candidates. The signs of wb and
  // wc are their numerators' (nn > 0), tested before dividing.
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const Vec3 n = ab.cross(ac);
  const double nn = n.squaredNorm();
  if (!(nn > 0.0)) return std::nullopt;
  const double bn = ap.cross(ac).dot(n), cn = ab.cross(ap).dot(n);
  if (!(bn >= 0.0 && cn >= 0.0)) return std::nullopt;
  const double wb = bn / nn, wc = cn / nn;
  const double wa = 1.0 - wb - wc;
  if (!(wa >= 0.0)) return std::nullopt;
  return Vec3(wa, wb, wc);
}

PointTriangleProximity pointTriangleProximity(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a;
  const Vec3 n = ab.cross(ac);

  double bestSquared = INFINITY;
  Vec3 weights(1.0, 0.0, 0.0);
  const auto consider = [&](const Vec3& w) {
    const double squared = (p - (w[0] * a + w[1] * b + w[2] * c)).squaredNorm();
    if (squared < bestSquared) {
      bestSquared = squared;
      weights = w;
    }
  };
  // The face: p's projection onto the plane, kept when it falls inside (a zero-area triangle has
  // no face region; a nearly degenerate one's ill-conditioned weights are made harmless by the
  // comparison with the edges below).
  if (const std::optional<Vec3> face = faceProjectionWeights(p, a, b, c)) consider(*face);
  // The edges, whose closest points include the vertices' regions.
  const double tab = closestSegmentParameter(p, a, b), tbc = closestSegmentParameter(p, b, c),
               tca = closestSegmentParameter(p, c, a);
  consider(Vec3(1.0 - tab, tab, 0.0));
  consider(Vec3(0.0, 1.0 - tbc, tbc));
  consider(Vec3(tca, 0.0, 1.0 - tca));

  PointTriangleProximity result;
  result.weights = weights;
  result.distance = std::sqrt(bestSquared);
  const Vec3 closest = weights[0] * a + weights[1] * b + weights[2] * c;
  if (result.distance > touchingDistance(largestCoordinate(p, a, b, c))) {
    result.normal = (p - closest) / result.distance;
  } else {
    const Vec3 longestEdge = std::max({ab, ac, Vec3(c - b)}, [](const Vec3& x, const Vec3& y) {
      return x.squaredNorm() < y.squaredNorm();
    });
    result.normal = touchingNormal(n, longestEdge);
  }
  return result;
}

namespace {

// The result for the closest points at (s, t), their squared distance given.
EdgeEdgeProximity edgeEdgeResult(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1, double s, double t,
                                 double squared) {
  const Vec3 u = p1 - p0, v = q1 - q0, w = p0 - q0;
  EdgeEdgeProximity result;
  result.s = s;
  result.t = t;
  result.distance = std::sqrt(squared);
  if (result.distance > touchingDistance(largestCoordinate(p0, p1, q0, q1))) {
    result.normal = (w + s * u - t * v) / result.distance;
  } else {
    result.normal = touchingNormal(u.cross(v), u.squaredNorm() >= v.squaredNorm() ? u : v);
  }
  return result;
}

}  // namespace

std::optional<EdgeEdgeProximity> edgeEdgeInteriorProximity(const Vec3& p0, const Vec3& p1, const Vec3& q0,
                                                           const Vec3& q1, double within) {
  const Vec3 u = p1 - p0, v = q1 - q0, w = p0 - q0;
  // As in edgeEdgeProximity: the squared distance is convex in (s, t), so a critical point
  // strictly inside the unit square is its minimum, and without one the minimum lies on the square's
  // boundary. s = sn / D and t = tn / D with D > 0, so the square is tested on the numerators first:
  // most pairs a repulsion pass meets (neighbours in a flat sheet) are rejected there without a
  // division.
  // At such a point the distance is the lines' along their common normal u x v: |w . (u x v)| / sqrt(D),
  // so `within` is tested without dividing too (with a margin far above rounding: the exact test
  // follows). The tests are combined without branching: which of them fails varies from pair to
  // pair, and a mispredicted branch costs more than the arithmetic. D = 0 (parallel edges) fails
  // them all.
  const Vec3 normal = u.cross(v);
  const double determinant = normal.squaredNorm();
  const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
  const double sn = uv * vw - vv * uw, tn = uu * vw - uv * uw, lineGap = w.dot(normal);
  if (!((sn > 0.0) & (sn < determinant) & (tn > 0.0) & (tn < determinant) &
        (lineGap * lineGap < (1.0 + 1e-6) * within * within * determinant)))
    return std::nullopt;
  const double s = sn / determinant, t = tn / determinant;
  if (!(s > 0.0 && s < 1.0 && t > 0.0 && t < 1.0)) return std::nullopt;  // a quotient rounded onto an end point
  const double squared = (w + s * u - t * v).squaredNorm();
  if (!(squared < within * within)) return std::nullopt;
  return edgeEdgeResult(p0, p1, q0, q1, s, t, squared);
}

EdgeEdgeProximity edgeEdgeProximity(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  const Vec3 u = p1 - p0, v = q1 - q0, w = p0 - q0;
  const Vec3 uxv = u.cross(v);

  double bestSquared = INFINITY;
  double bestS = 0.0, bestT = 0.0;
  const auto consider = [&](double s, double t) {
    const double squared = (w + s * u - t * v).squaredNorm();
    if (squared < bestSquared) {
      bestSquared = squared;
      bestS = s;
      bestT = t;
    }
  };
  // The lines' common perpendicular, kept when its feet lie on both edges. |u x v|^2 is the normal
  // equations' determinant (computed from the cross product, which keeps its accuracy for nearly
  // parallel edges); parallel or degenerate edges have no unique interior solution, and their
  // minimum is also attained on the boundary below.
  const double determinant = uxv.squaredNorm();
  if (determinant > 0.0) {
    const double uu = u.dot(u), uv = u.dot(v), vv = v.dot(v), uw = u.dot(w), vw = v.dot(w);
    const double s = (uv * vw - vv * uw) / determinant, t = (uu * vw - uv * uw) / determinant;
    if (s >= 0.0 && s <= 1.0 && t >= 0.0 && t <= 1.0) consider(s, t);
  }
  // The squared distance is convex in (s, t), so outside the interior its minimum over the unit
  // square lies on the square's boundary: an endpoint of one edge against the other edge.
  consider(0.0, closestSegmentParameter(p0, q0, q1));
  consider(1.0, closestSegmentParameter(p1, q0, q1));
  consider(closestSegmentParameter(q0, p0, p1), 0.0);
  consider(closestSegmentParameter(q1, p0, p1), 1.0);

  return edgeEdgeResult(p0, p1, q0, q1, bestS, bestT, bestSquared);
}

}  // namespace msim::solids
