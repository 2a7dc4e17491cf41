#pragma once
// Closest points between cloth primitives, the narrow phase's distance measure (Bridson, Fedkiw &
// Anderson 2002 sec. 6; Selle ch. 6.3): a particle against a triangle and an edge against an edge.
// Repulsions push along `normal` with the barycentric `weights` (or s, t) spreading the impulse onto
// the primitives' vertices, and continuous collision detection checks these distances at the times
// the four points are coplanar. Both functions are exact up to rounding over every Voronoi region
// (face, edges, vertices) and stay well defined for zero-area triangles and zero-length or parallel
// edges: they compare the interior candidate, when it exists, with the closest points on the
// boundary, so an ill-conditioned interior solve can never return a point farther than a boundary one.
#include <cmath>
#include <optional>

#include "msim/core/vec.hpp"

namespace msim::solids {

struct PointTriangleProximity {
  double distance = 0.0;
  Vec3 weights = Vec3::Zero();  // barycentric w1, w2, w3 of the closest point w1 a + w2 b + w3 c, each in [0, 1], sum 1
  Vec3 normal = Vec3::Zero();   // unit, from the closest point towards p; the triangle's normal when p lies on it
};

PointTriangleProximity pointTriangleProximity(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// The barycentric weights (of a, b, c) of p's projection onto the triangle's plane when it falls on
// the face, each >= 0 (then it is the closest point); nullopt when it falls outside or the triangle
// has no area. The cheap test of repulsions, which act only over faces.
std::optional<Vec3> faceProjectionWeights(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

struct EdgeEdgeProximity {
  double distance = 0.0;
  double s = 0.0, t = 0.0;     // closest points p0 + s (p1 - p0) and q0 + t (q1 - q0), s and t in [0, 1]
  Vec3 normal = Vec3::Zero();  // unit, from the second edge's point towards the first's; (p1-p0) x (q1-q0) when they touch
};

EdgeEdgeProximity edgeEdgeProximity(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1);

// edgeEdgeProximity when its closest points lie strictly inside both edges (the lines' common
// perpendicular: the only case repulsions act on, the end points being the point-face pairs'),
// else nullopt; skips the four end-point candidates, which then cannot be the closest. Also nullopt
// when they lie `within` or farther apart (the repulsions' reach).
std::optional<EdgeEdgeProximity> edgeEdgeInteriorProximity(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                                                           double within = INFINITY);

}  // namespace msim::solids
