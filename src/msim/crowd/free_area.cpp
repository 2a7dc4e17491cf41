#include "msim/crowd/free_area.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <vector>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"

namespace msim::crowd {
namespace {

double cross(const Vec2& a, const Vec2& b) { return a.x() * b.y() - a.y() * b.x(); }

double shoelace(const std::vector<Vec2>& v) {
  double twice = 0.0;
  for (std::size_t i = 0, j = v.size() - 1; i < v.size(); j = i++) twice += cross(v[j], v[i]);
  return 0.5 * std::abs(twice);
}

// One Sutherland-Hodgman pass: keeps the part of `in` with sign * (x[axis] - bound) >= 0.
void clipHalfPlane(const std::vector<Vec2>& in, std::vector<Vec2>& out, int axis, double bound, double sign) {
  out.clear();
  if (in.empty()) return;
  Vec2 prev = in.back();
  double dPrev = sign * (prev[axis] - bound);
  for (const Vec2& cur : in) {
    const double d = sign * (cur[axis] - bound);
    if ((d >= 0.0) != (dPrev >= 0.0)) {
      const double t = dPrev / (dPrev - d);
      Vec2 x = prev + t * (cur - prev);
      x[axis] = bound;  // exact on the clip line, so slivers along it have zero area
      out.push_back(x);
    }
    if (d >= 0.0) out.push_back(cur);
    prev = cur;
    dPrev = d;
  }
}

double clipArea(const Polygon& polygon, const Vec2& lo, const Vec2& hi, std::vector<Vec2>& a, std::vector<Vec2>& b) {
  a.assign(polygon.vertices.begin(), polygon.vertices.end());
  clipHalfPlane(a, b, 0, lo.x(), 1.0);
  clipHalfPlane(b, a, 0, hi.x(), -1.0);
  clipHalfPlane(a, b, 1, lo.y(), 1.0);
  clipHalfPlane(b, a, 1, hi.y(), -1.0);
  return a.size() < 3 ? 0.0 : shoelace(a);
}

// Signed area of the disc of radius r at the origin ∩ the triangle (0, a, b): the triangle part
// inside the circle plus the circular sectors where the edge ab runs outside it. Summed over the
// edges of a polygon this is the exact disc ∩ polygon area (signed by orientation).
double discTriangleArea(const Vec2& a, const Vec2& b, double r) {
  const double r2 = r * r;
  auto sector = [&](const Vec2& u, const Vec2& v) { return 0.5 * r2 * std::atan2(cross(u, v), u.dot(v)); };
  if (a.squaredNorm() <= r2 && b.squaredNorm() <= r2) return 0.5 * cross(a, b);
  const Vec2 d = b - a;
  const double A = d.squaredNorm(), B = a.dot(d), C = a.squaredNorm() - r2;
  const double disc = B * B - A * C;
  if (A == 0.0 || disc <= 0.0) return sector(a, b);
  const double s = std::sqrt(disc);
  const double t1 = (-B - s) / A, t2 = (-B + s) / A;
  if (t2 <= 0.0 || t1 >= 1.0) return sector(a, b);
  const Vec2 p1 = a + std::max(t1, 0.0) * d, p2 = a + std::min(t2, 1.0) * d;
  return sector(a, p1) + 0.5 * cross(p1, p2) + sector(p2, b);
}

// Index range of the cells overlapping [lo, hi] along each axis, clamped to the grid; empty when
// the box misses the grid.
bool cellRange(const GridSpec<2>& g, const Vec2& lo, const Vec2& hi, IVec2& first, IVec2& last) {
  for (int a = 0; a < 2; ++a) {
    first[a] = std::max(0, static_cast<int>(std::floor((lo[a] - g.origin[a]) / g.dx)));
    last[a] = std::min(g.res[a] - 1, static_cast<int>(std::floor((hi[a] - g.origin[a]) / g.dx)));
    if (first[a] > last[a]) return false;
  }
  return true;
}

}  // namespace

double clippedArea(const Polygon& polygon, const Vec2& lo, const Vec2& hi) {
  std::vector<Vec2> a, b;
  return clipArea(polygon, lo, hi, a, b);
}

double discRectangleArea(const Vec2& centre, double radius, const Vec2& lo, const Vec2& hi) {
  if (!(radius > 0.0) || hi.x() <= lo.x() || hi.y() <= lo.y()) return 0.0;
  // Fast paths: the rectangle inside the disc, the disc inside the rectangle, or no overlap.
  const Vec2 far = (centre - lo).cwiseAbs().cwiseMax((hi - centre).cwiseAbs());
  if (far.squaredNorm() <= radius * radius) return (hi - lo).prod();
  const Vec2 near = (lo - centre).cwiseMax(centre - hi).cwiseMax(Vec2::Zero());
  if (near.squaredNorm() >= radius * radius) return 0.0;
  if ((centre - lo).minCoeff() >= radius && (hi - centre).minCoeff() >= radius)
    return std::numbers::pi * radius * radius;
  const Vec2 corners[4] = {lo - centre, Vec2(hi.x(), lo.y()) - centre, hi - centre, Vec2(lo.x(), hi.y()) - centre};
  double area = 0.0;  // counter-clockwise corners: positive
  for (int k = 0; k < 4; ++k) area += discTriangleArea(corners[k], corners[(k + 1) % 4], radius);
  return std::clamp(area, 0.0, (hi - lo).prod());
}

FreeArea::FreeArea(const GridSpec<2>& grid)
    : grid_(grid), static_(grid, 0.0), covered_(grid, 0.0), fraction_(grid, 1.0f) {}

void FreeArea::addStaticObstacle(const Polygon& polygon) {
  addPolygon(polygon, static_);
  covered_.data() = static_.data();
  refreshFraction();
}

void FreeArea::addPolygon(const Polygon& polygon, Grid<double, 2>& coverage) {
  if (polygon.size() < 3)
    throw InputError(fmt::format("free area: obstacle polygon has {} vertices, need at least 3", polygon.size()));
  for (const Vec2& v : polygon.vertices)
    if (!v.allFinite()) throw InputError("free area: obstacle polygon has a non-finite vertex");
  Vec2 lo, hi;
  bounds(polygon, lo, hi);
  IVec2 first, last;
  if (!cellRange(grid_, lo, hi, first, last)) return;
  for (int j = first.y(); j <= last.y(); ++j)
    for (int i = first.x(); i <= last.x(); ++i) {
      const Vec2 cellLo = grid_.origin + Vec2(i, j) * grid_.dx;
      coverage(IVec2(i, j)) += clipArea(polygon, cellLo, cellLo + Vec2::Constant(grid_.dx), clipA_, clipB_);
    }
}

void FreeArea::update(std::span<const Vec2f> centres, std::span<const float> radii, std::span<const Polygon> moving) {
  if (centres.size() != radii.size())
    throw InputError(fmt::format("free area: {} disc centres but {} radii", centres.size(), radii.size()));
  std::copy(static_.data().begin(), static_.data().end(), covered_.data().begin());
  for (const Polygon& polygon : moving) addPolygon(polygon, covered_);
  // Serial: a disc touches a few cells, and neighbouring discs share cells.
  for (std::size_t k = 0; k < centres.size(); ++k) {
    if (!centres[k].allFinite() || !std::isfinite(radii[k]) || radii[k] < 0.0f)
      throw InputError(fmt::format("free area: disc {} has a non-finite centre or an invalid radius", k));
    const Vec2 c = centres[k].cast<double>();
    const double r = radii[k];
    IVec2 first, last;
    if (r == 0.0 || !cellRange(grid_, c - Vec2::Constant(r), c + Vec2::Constant(r), first, last)) continue;
    for (int j = first.y(); j <= last.y(); ++j)
      for (int i = first.x(); i <= last.x(); ++i) {
        const Vec2 cellLo = grid_.origin + Vec2(i, j) * grid_.dx;
        covered_(IVec2(i, j)) += discRectangleArea(c, r, cellLo, cellLo + Vec2::Constant(grid_.dx));
      }
  }
  refreshFraction();
}

void FreeArea::refreshFraction() {
  const double cellArea = grid_.dx * grid_.dx;
  parallelFor(0, fraction_.count(), [&](std::size_t i) {
    fraction_[i] = static_cast<float>(1.0 - std::clamp(covered_[i] / cellArea, 0.0, 1.0));
  });
}

}  // namespace msim::crowd
