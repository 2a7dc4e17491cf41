#include "msim/rigid/polyhedron_contact.hpp"

#include <algorithm>
#include <array>
#include <limits>
#include <utility>

#include "msim/rigid/polyhedron.hpp"

namespace msim::rigid {
namespace {

constexpr double kInf = std::numeric_limits<double>::infinity();
// Feature preference (Box2D's b2CollidePolygons): the other candidate must beat the current
// separation by 2% plus 1e-4 of the smaller body size to take over.
constexpr double kRelativeTol = 0.98;
constexpr double kAbsoluteTol = 1e-4;

// A polyhedron's features in world coordinates (indices as in `mesh`).
struct WorldHull {
  const ConvexMesh& mesh;
  std::vector<Vec3> vertices;
  std::vector<Vec3> normals;
  std::vector<double> offsets;
  std::vector<Vec3> edgeDirections;
  double radius = 0.0;  // about the pose origin
};

WorldHull place(const ConvexMesh& m, const Pose& pose) {
  WorldHull h{m, {}, {}, {}, {}, 0.0};
  for (const Vec3& v : m.vertices) {
    h.vertices.push_back(pose.toWorld(v));
    h.radius = std::max(h.radius, v.norm());
  }
  for (const ConvexFace& f : m.faces) {
    h.normals.push_back(pose.rotation * f.normal);
    h.offsets.push_back(f.offset + h.normals.back().dot(pose.position));
  }
  for (const Vec3& e : m.edgeDirections) h.edgeDirections.push_back(pose.rotation * e);
  return h;
}

std::pair<double, double> extent(const std::vector<Vec3>& vertices, const Vec3& axis) {
  double lo = kInf, hi = -kInf;
  for (const Vec3& v : vertices) {
    lo = std::min(lo, axis.dot(v));
    hi = std::max(hi, axis.dot(v));
  }
  return {lo, hi};
}

struct FaceQuery {
  int face = -1;
  double separation = -kInf;
};

// Largest distance of `other` in front of a face plane of `ref`.
FaceQuery queryFaces(const WorldHull& ref, const WorldHull& other) {
  FaceQuery q;
  for (std::size_t f = 0; f < ref.normals.size(); ++f) {
    const double s = extent(other.vertices, ref.normals[f]).first - ref.offsets[f];
    if (s > q.separation) q = {static_cast<int>(f), s};
  }
  return q;
}

struct EdgeQuery {
  Vec3 axis = Vec3::Zero();  // unit, from a towards b
  int edgeA = -1, edgeB = -1;  // indices into edgeDirections
  double separation = -kInf;
};

EdgeQuery queryEdges(const WorldHull& a, const WorldHull& b) {
  EdgeQuery q;
  for (std::size_t i = 0; i < a.edgeDirections.size(); ++i)
    for (std::size_t j = 0; j < b.edgeDirections.size(); ++j) {
      Vec3 axis = a.edgeDirections[i].cross(b.edgeDirections[j]);
      const double len = axis.norm();
      if (len < kParallelSine) continue;  // parallel edges: their axes are face normals
      axis /= len;
      const auto [loA, hiA] = extent(a.vertices, axis);
      const auto [loB, hiB] = extent(b.vertices, axis);
      // Both orientations: b may lie on either side of a along this axis.
      const double sep = std::max(loB - hiA, loA - hiB);
      if (sep > q.separation)
        q = {loB - hiA >= loA - hiB ? axis : Vec3(-axis), static_cast<int>(i), static_cast<int>(j),
             sep};
    }
  return q;
}

// Keeps the side of the plane side . x <= c.
std::vector<Vec3> clip(const std::vector<Vec3>& polygon, const Vec3& side, double c) {
  std::vector<Vec3> out;
  const std::size_t n = polygon.size();
  for (std::size_t k = 0; k < n; ++k) {
    const Vec3& p = polygon[k];
    const Vec3& q = polygon[(k + 1) % n];
    const double dp = side.dot(p) - c, dq = side.dot(q) - c;
    if (dp <= 0.0) out.push_back(p);
    if ((dp < 0.0 && dq > 0.0) || (dp > 0.0 && dq < 0.0)) out.push_back(p + (q - p) * (dp / (dp - dq)));
  }
  return out;
}

struct ClipPoint {
  Vec3 point;
  double depth;
};

// At most 4 of the points: the deepest (it carries the penetration), the farthest from it, and
// the farthest on either side of the line through those two, which keeps the support polygon
// (what resists tipping) close to the full one.
std::vector<ClipPoint> reduceToFour(const std::vector<ClipPoint>& pts, const Vec3& normal) {
  if (pts.size() <= 4) return pts;
  auto argBest = [&](auto score) {
    std::size_t best = 0;
    for (std::size_t k = 1; k < pts.size(); ++k)
      if (score(pts[k]) > score(pts[best])) best = k;
    return best;
  };
  const std::size_t i1 = argBest([](const ClipPoint& c) { return c.depth; });
  const Vec3 p1 = pts[i1].point;
  const std::size_t i2 = argBest([&](const ClipPoint& c) { return (c.point - p1).squaredNorm(); });
  const Vec3 diagonal = pts[i2].point - p1;
  auto area = [&](const ClipPoint& c) { return diagonal.cross(c.point - p1).dot(normal); };
  const std::size_t i3 = argBest(area);
  const std::size_t i4 = argBest([&](const ClipPoint& c) { return -area(c); });
  std::vector<ClipPoint> out{pts[i1], pts[i2]};
  if (area(pts[i3]) > 0.0) out.push_back(pts[i3]);
  if (area(pts[i4]) < 0.0) out.push_back(pts[i4]);
  return out;
}

// Face `f` of `ref` against the most anti-parallel face of `inc`. `refIsA` says which body
// owns the reference face, for the Contact convention.
void faceContacts(const WorldHull& ref, int f, const WorldHull& inc, bool refIsA, int ia, int ib,
                  double margin, std::vector<Contact>& out) {
  const Vec3& n = ref.normals[f];
  std::size_t g = 0;
  for (std::size_t k = 1; k < inc.normals.size(); ++k)
    if (inc.normals[k].dot(n) < inc.normals[g].dot(n)) g = k;
  std::vector<Vec3> polygon;
  for (int i : inc.mesh.faces[g].loop) polygon.push_back(inc.vertices[i]);
  const std::vector<int>& loop = ref.mesh.faces[f].loop;
  for (std::size_t k = 0; k < loop.size() && !polygon.empty(); ++k) {
    const Vec3& p = ref.vertices[loop[k]];
    const Vec3& q = ref.vertices[loop[(k + 1) % loop.size()]];
    const Vec3 side = (q - p).cross(n);  // outward for a counter-clockwise loop
    polygon = clip(polygon, side, side.dot(p));
  }
  std::vector<ClipPoint> points;
  for (const Vec3& p : polygon) {
    const double depth = ref.offsets[f] - n.dot(p);
    if (depth >= -margin) points.push_back({p, depth});
  }
  for (const ClipPoint& c : reduceToFour(points, n)) {
    // The clipped point lies on the incident face; moved onto the reference face it is on b.
    if (refIsA)
      out.push_back({ia, ib, c.point, -n, c.depth, 0.0, 0.0});
    else
      out.push_back({ia, ib, c.point + c.depth * n, n, c.depth, 0.0, 0.0});
  }
}

// The edge of `h` parallel to `direction` that reaches farthest along `axis`.
std::array<Vec3, 2> supportingEdge(const WorldHull& h, const Vec3& direction, const Vec3& axis) {
  std::array<Vec3, 2> best{};
  double reach = -kInf;
  for (const auto& e : h.mesh.edges) {
    const Vec3& p = h.vertices[e[0]];
    const Vec3& q = h.vertices[e[1]];
    if ((q - p).normalized().cross(direction).norm() >= kParallelSine) continue;
    const double r = std::min(axis.dot(p), axis.dot(q));
    if (r > reach) reach = r, best = {p, q};
  }
  return best;
}

// Closest points of segments p1q1 and p2q2 (Ericson 2005, 5.1.9), both of non-zero length.
std::pair<Vec3, Vec3> closestSegmentPoints(const Vec3& p1, const Vec3& q1, const Vec3& p2,
                                           const Vec3& q2) {
  const Vec3 d1 = q1 - p1, d2 = q2 - p2, r = p1 - p2;
  const double a = d1.squaredNorm(), e = d2.squaredNorm(), f = d2.dot(r);
  const double c = d1.dot(r), b = d1.dot(d2), denom = a * e - b * b;
  double s = denom > 0.0 ? std::clamp((b * f - c * e) / denom, 0.0, 1.0) : 0.0;
  double t = (b * s + f) / e;
  if (t < 0.0) {
    t = 0.0;
    s = std::clamp(-c / a, 0.0, 1.0);
  } else if (t > 1.0) {
    t = 1.0;
    s = std::clamp((b - c) / a, 0.0, 1.0);
  }
  return {p1 + s * d1, p2 + t * d2};
}

}  // namespace

void collidePolyhedra(const ConvexMesh& a, const Pose& pa, int ia, const ConvexMesh& b,
                      const Pose& pb, int ib, double margin, std::vector<Contact>& out) {
  const WorldHull A = place(a, pa), B = place(b, pb);
  const FaceQuery faceA = queryFaces(A, B);
  if (faceA.separation > margin) return;
  const FaceQuery faceB = queryFaces(B, A);
  if (faceB.separation > margin) return;
  const EdgeQuery edge = queryEdges(A, B);
  if (edge.separation > margin) return;

  const double tol = kAbsoluteTol * std::min(A.radius, B.radius);
  const bool useB = faceB.separation > kRelativeTol * faceA.separation + tol;
  const double faceSeparation = useB ? faceB.separation : faceA.separation;
  if (edge.separation > kRelativeTol * faceSeparation + tol) {
    const auto ea = supportingEdge(A, A.edgeDirections[edge.edgeA], edge.axis);
    const auto eb = supportingEdge(B, B.edgeDirections[edge.edgeB], -edge.axis);
    const Vec3 onB = closestSegmentPoints(ea[0], ea[1], eb[0], eb[1]).second;
    out.push_back({ia, ib, onB, -edge.axis, -edge.separation, 0.0, 0.0});
  } else if (useB) {
    faceContacts(B, faceB.face, A, false, ia, ib, margin, out);
  } else {
    faceContacts(A, faceA.face, B, true, ia, ib, margin, out);
  }
}

}  // namespace msim::rigid
