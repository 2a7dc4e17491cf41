#include "msim/geometry/triangle_queries.hpp"

#include <cmath>

#include <Eigen/Geometry>

namespace msim::geometry {

// Ericson, Real-Time Collision Detection, 5.1.5: find the Voronoi region of p (vertex, edge or
// face) from barycentric-style dot products, then project onto that feature.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ab = b - a, ac = c - a, ap = p - a;
  const double d1 = ab.dot(ap), d2 = ac.dot(ap);
  if (d1 <= 0.0 && d2 <= 0.0) return a;

  const Vec3 bp = p - b;
  const double d3 = ab.dot(bp), d4 = ac.dot(bp);
  if (d3 >= 0.0 && d4 <= d3) return b;

  const double vc = d1 * d4 - d3 * d2;
  if (vc <= 0.0 && d1 >= 0.0 && d3 <= 0.0) return a + (d1 / (d1 - d3)) * ab;

  const Vec3 cp = p - c;
  const double d5 = ab.dot(cp), d6 = ac.dot(cp);
  if (d6 >= 0.0 && d5 <= d6) return c;

  const double vb = d5 * d2 - d1 * d6;
  if (vb <= 0.0 && d2 >= 0.0 && d6 <= 0.0) return a + (d2 / (d2 - d6)) * ac;

  const double va = d3 * d6 - d5 * d4;
  if (va <= 0.0 && (d4 - d3) >= 0.0 && (d5 - d6) >= 0.0) return b + ((d4 - d3) / ((d4 - d3) + (d5 - d6))) * (c - b);

  const double denom = va + vb + vc;
  if (denom == 0.0) return a;  // zero-area triangle whose edges all failed the tests above
  const double v = vb / denom, w = vc / denom;
  return a + v * ab + w * ac;
}

double solidAngle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  const Vec3 ra = a - p, rb = b - p, rc = c - p;
  const double la = ra.norm(), lb = rb.norm(), lc = rc.norm();
  const double numerator = ra.dot(rb.cross(rc));
  const double denominator = la * lb * lc + ra.dot(rb) * lc + rb.dot(rc) * la + rc.dot(ra) * lb;
  return 2.0 * std::atan2(numerator, denominator);
}

}  // namespace msim::geometry
