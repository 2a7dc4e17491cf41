#pragma once
// Planar polygons for crowd scenes: static and moving obstacles, goal and exit regions, inflow
// regions. A polygon is a closed chain of vertices (the last joins the first) in either
// orientation; obstacles must be simple (no self-intersection), which validateSimple() checks.
#include <optional>
#include <string>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::crowd {

struct Polygon {
  std::vector<Vec2> vertices;  // >= 3, either orientation [m]

  std::size_t size() const { return vertices.size(); }
  const Vec2& vertex(std::size_t i) const { return vertices[i % vertices.size()]; }
};

// Signed area: positive for counter-clockwise vertices [m^2].
double signedArea(const Polygon& polygon);
// Axis-aligned bounds.
void bounds(const Polygon& polygon, Vec2& lo, Vec2& hi);
// Point in polygon by the even-odd rule; points on the boundary may go either way.
bool contains(const Polygon& polygon, const Vec2& point);
// Closest point on the boundary (edges) of the polygon.
Vec2 closestBoundaryPoint(const Polygon& polygon, const Vec2& point);
// Distance to the boundary, negative inside (signed distance) [m].
double signedDistance(const Polygon& polygon, const Vec2& point);
// Closest point on segment [a, b] to p.
Vec2 closestPointOnSegment(const Vec2& a, const Vec2& b, const Vec2& p);
// True if the closed segments [a, b] and [c, d] intersect (touching counts).
bool segmentsIntersect(const Vec2& a, const Vec2& b, const Vec2& c, const Vec2& d);
// True if the open segment (a, b) crosses an edge of the polygon or runs through its inside.
bool segmentHitsPolygon(const Polygon& polygon, const Vec2& a, const Vec2& b);

// Distance between two polygons' closed regions: 0 where they touch, overlap or one holds the
// other [m].
double polygonDistance(const Polygon& a, const Polygon& b);
// The narrowest passage of a walkable box [lo, hi] with these obstacles: the least gap, between
// two obstacles or between an obstacle and the box's sides, that is at least `minWidth` wide
// (narrower gaps pass no one and are walls in effect) [m]; infinity without one.
double narrowestPassage(const std::vector<Polygon>& obstacles, const Vec2& lo, const Vec2& hi, double minWidth);

// Throws InputError("<what>: ...") if the polygon has fewer than 3 vertices, a non-finite or
// repeated vertex, zero area, or two non-adjacent edges that intersect (the message names the
// edges). `what` names the object for the user, e.g. "obstacles[3]".
void validateSimple(const Polygon& polygon, const std::string& what);

// Axis-aligned rectangle and regular n-gon approximating a circle, counter-clockwise.
Polygon rectangle(const Vec2& lo, const Vec2& hi);
Polygon regularPolygon(const Vec2& centre, double radius, int sides);

}  // namespace msim::crowd
