#include "msim/crowd/polygon.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <fmt/format.h>

#include "msim/core/error.hpp"

namespace msim::crowd {
namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

// Orientation of c relative to the directed line a -> b: +1 left, -1 right, 0 collinear.
int orientation(const Vec2& a, const Vec2& b, const Vec2& c) {
  const double v = cross(b - a, c - a);
  const double scale = (b - a).squaredNorm() + (c - a).squaredNorm();
  if (std::abs(v) <= 1e-14 * scale) return 0;
  return v > 0 ? 1 : -1;
}

bool onSegment(const Vec2& a, const Vec2& b, const Vec2& p) {
  return p.x() >= std::min(a.x(), b.x()) && p.x() <= std::max(a.x(), b.x()) && p.y() >= std::min(a.y(), b.y()) &&
         p.y() <= std::max(a.y(), b.y());
}

}  // namespace

double signedArea(const Polygon& polygon) {
  double twice = 0.0;
  for (std::size_t i = 0; i < polygon.size(); ++i) twice += cross(polygon.vertex(i), polygon.vertex(i + 1));
  return 0.5 * twice;
}

void bounds(const Polygon& polygon, Vec2& lo, Vec2& hi) {
  lo = Vec2::Constant(std::numeric_limits<double>::infinity());
  hi = -lo;
  for (const Vec2& v : polygon.vertices) {
    lo = lo.cwiseMin(v);
    hi = hi.cwiseMax(v);
  }
}

bool contains(const Polygon& polygon, const Vec2& point) {
  bool inside = false;
  const std::size_t n = polygon.size();
  for (std::size_t i = 0, j = n - 1; i < n; j = i++) {
    const Vec2& a = polygon.vertices[i];
    const Vec2& b = polygon.vertices[j];
    if ((a.y() > point.y()) != (b.y() > point.y())) {
      const double xCross = a.x() + (point.y() - a.y()) / (b.y() - a.y()) * (b.x() - a.x());
      if (point.x() < xCross) inside = !inside;
    }
  }
  return inside;
}

Vec2 closestPointOnSegment(const Vec2& a, const Vec2& b, const Vec2& p) {
  const Vec2 ab = b - a;
  const double len2 = ab.squaredNorm();
  if (len2 == 0.0) return a;
  const double t = std::clamp((p - a).dot(ab) / len2, 0.0, 1.0);
  return a + t * ab;
}

Vec2 closestBoundaryPoint(const Polygon& polygon, const Vec2& point) {
  Vec2 best = polygon.vertex(0);
  double bestDistance2 = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < polygon.size(); ++i) {
    const Vec2 q = closestPointOnSegment(polygon.vertex(i), polygon.vertex(i + 1), point);
    const double d2 = (q - point).squaredNorm();
    if (d2 < bestDistance2) {
      bestDistance2 = d2;
      best = q;
    }
  }
  return best;
}

double signedDistance(const Polygon& polygon, const Vec2& point) {
  const double d = (closestBoundaryPoint(polygon, point) - point).norm();
  return contains(polygon, point) ? -d : d;
}

bool segmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d) {
  const int o1 = orientation(a, b, c), o2 = orientation(a, b, d);
  const int o3 = orientation(c, d, a), o4 = orientation(c, d, b);
  if (o1 != o2 && o3 != o4) return true;
  return (o1 == 0 && onSegment(a, b, c)) || (o2 == 0 && onSegment(a, b, d)) || (o3 == 0 && onSegment(c, d, a)) ||
         (o4 == 0 && onSegment(c, d, b));
}

bool segmentHitsPolygon(const Polygon& polygon, const Vec2& a, const Vec2& b) {
  // A segment that crosses no edge lies wholly inside or wholly outside; its midpoint decides.
  // Touching a vertex or running along an edge counts as a hit: sight lines that graze an
  // obstacle corner are not clear for an agent of non-zero radius either.
  for (std::size_t i = 0; i < polygon.size(); ++i)
    if (segmentsIntersect(a, b, polygon.vertex(i), polygon.vertex(i + 1))) return true;
  return contains(polygon, 0.5 * (a + b));
}

double polygonDistance(const Polygon& a, const Polygon& b) {
  if (contains(a, b.vertex(0)) || contains(b, a.vertex(0))) return 0.0;
  double best = std::numeric_limits<double>::infinity();
  for (std::size_t i = 0; i < a.size(); ++i) {
    const Vec2 &p = a.vertex(i), &q = a.vertex(i + 1);
    for (std::size_t j = 0; j < b.size(); ++j) {
      const Vec2 &r = b.vertex(j), &s = b.vertex(j + 1);
      if (segmentsIntersect(p, q, r, s)) return 0.0;
      // Two disjoint segments are closest at an end point of one of them.
      best = std::min({best, (closestPointOnSegment(p, q, r) - r).norm(), (closestPointOnSegment(p, q, s) - s).norm(),
                       (closestPointOnSegment(r, s, p) - p).norm(), (closestPointOnSegment(r, s, q) - q).norm()});
    }
  }
  return best;
}

double narrowestPassage(const std::vector<Polygon>& obstacles, const Vec2& lo, const Vec2& hi, double minWidth) {
  double best = std::numeric_limits<double>::infinity();
  auto consider = [&](double gap) {
    if (gap >= minWidth) best = std::min(best, gap);
  };
  std::vector<Vec2> boxLo(obstacles.size()), boxHi(obstacles.size());
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    bounds(obstacles[k], boxLo[k], boxHi[k]);
    for (int a = 0; a < 2; ++a) {
      if (boxLo[k][a] > lo[a]) consider(boxLo[k][a] - lo[a]);
      if (boxHi[k][a] < hi[a]) consider(hi[a] - boxHi[k][a]);
    }
  }
  for (std::size_t k = 0; k < obstacles.size(); ++k)
    for (std::size_t m = k + 1; m < obstacles.size(); ++m) {
      // The bounds' gap is a lower bound of the polygons' distance: pairs farther apart than the
      // narrowest passage found so far cannot narrow it.
      const Vec2 gap = (boxLo[m] - boxHi[k]).cwiseMax(boxLo[k] - boxHi[m]).cwiseMax(0.0);
      if (gap.norm() >= best) continue;
      consider(polygonDistance(obstacles[k], obstacles[m]));
    }
  return best;
}

void validateSimple(const Polygon& polygon, const std::string& what) {
  const std::size_t n = polygon.size();
  if (n < 3) throw InputError(fmt::format("{}: a polygon needs at least 3 vertices, got {}", what, n));
  for (std::size_t i = 0; i < n; ++i) {
    if (!polygon.vertices[i].allFinite())
      throw InputError(fmt::format("{}: vertex {} is not a finite number", what, i));
    if (polygon.vertex(i) == polygon.vertex(i + 1))
      throw InputError(fmt::format("{}: vertices {} and {} coincide", what, i, (i + 1) % n));
  }
  Vec2 lo, hi;
  bounds(polygon, lo, hi);
  const double extent = (hi - lo).maxCoeff();
  if (std::abs(signedArea(polygon)) <= 1e-12 * extent * extent)
    throw InputError(fmt::format("{}: the polygon has zero area", what));
  for (std::size_t i = 0; i < n; ++i)
    for (std::size_t j = i + 2; j < n; ++j) {
      if (i == 0 && j == n - 1) continue;  // adjacent through the closing edge
      if (segmentsIntersect(polygon.vertex(i), polygon.vertex(i + 1), polygon.vertex(j), polygon.vertex(j + 1)))
        throw InputError(fmt::format("{}: edges {} and {} intersect; the polygon must be simple (not self-intersecting)",
                                     what, i, j));
    }
}

Polygon rectangle(const Vec2& lo, const Vec2& hi) {
  return Polygon{{lo, Vec2(hi.x(), lo.y()), hi, Vec2(lo.x(), hi.y())}};
}

Polygon regularPolygon(const Vec2& centre, double radius, int sides) {
  Polygon p;
  p.vertices.reserve(sides);
  for (int k = 0; k < sides; ++k) {
    const double a = 2.0 * M_PI * k / sides;
    p.vertices.push_back(centre + radius * Vec2(std::cos(a), std::sin(a)));
  }
  return p;
}

}  // namespace msim::crowd
