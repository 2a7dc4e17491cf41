#include "msim/rigid/shapes.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

namespace msim::rigid {

SurfacePoint closestSurfacePoint(const Sphere& s, const Vec3& p) {
  const double dist = p.norm();
  // At the centre every direction is nearest; +z keeps the result deterministic.
  const Vec3 n = dist > 0.0 ? Vec3(p / dist) : Vec3(Vec3::UnitZ());
  return {n * s.radius, n, dist - s.radius};
}

SurfacePoint closestSurfacePoint(const Box& b, const Vec3& p) {
  const Vec3& h = b.halfExtents;
  const Vec3 q = p.cwiseMax(-h).cwiseMin(h);
  if ((p - q).squaredNorm() > 0.0) {
    const double dist = (p - q).norm();
    return {q, (p - q) / dist, dist};
  }
  int axis = 0;  // inside: the nearest face
  for (int k = 1; k < 3; ++k)
    if (h[k] - std::abs(p[k]) < h[axis] - std::abs(p[axis])) axis = k;
  SurfacePoint s{p, Vec3::Zero(), std::abs(p[axis]) - h[axis]};
  s.normal[axis] = p[axis] >= 0.0 ? 1.0 : -1.0;
  s.point[axis] = s.normal[axis] * h[axis];
  return s;
}

namespace {

Vec3 closestOnSegment(const Vec3& a, const Vec3& b, const Vec3& p) {
  const Vec3 ab = b - a;
  const double t = std::clamp((p - a).dot(ab) / std::max(ab.squaredNorm(), 1e-300), 0.0, 1.0);
  return a + t * ab;
}

}  // namespace

// Inside: the nearest face plane (exact for a convex body). Outside: the nearest point lies on a
// face whose plane has the point in front (its normal cone is spanned by such faces), so only
// those faces are searched, each by projection onto its polygon or else its nearest edge.
SurfacePoint closestSurfacePoint(const ConvexMesh& m, const Vec3& p) {
  int nearestFace = 0;
  double maxPlane = -std::numeric_limits<double>::infinity();
  for (std::size_t f = 0; f < m.faces.size(); ++f) {
    const double d = m.faces[f].normal.dot(p) - m.faces[f].offset;
    if (d > maxPlane) maxPlane = d, nearestFace = static_cast<int>(f);
  }
  const ConvexFace& nearest = m.faces[nearestFace];
  if (maxPlane <= 0.0) return {p - maxPlane * nearest.normal, nearest.normal, maxPlane};
  Vec3 best = p;
  double bestSq = std::numeric_limits<double>::infinity();
  for (const ConvexFace& face : m.faces) {
    const double d = face.normal.dot(p) - face.offset;
    if (d <= 0.0) continue;
    const Vec3 projected = p - d * face.normal;
    const std::size_t n = face.loop.size();
    bool inside = true;
    for (std::size_t k = 0; k < n && inside; ++k) {
      const Vec3& a = m.vertices[face.loop[k]];
      const Vec3& b = m.vertices[face.loop[(k + 1) % n]];
      inside = (b - a).cross(face.normal).dot(projected - a) <= 0.0;
    }
    if (inside) {
      if (d * d < bestSq) bestSq = d * d, best = projected;
      continue;
    }
    for (std::size_t k = 0; k < n; ++k) {
      const Vec3 q = closestOnSegment(m.vertices[face.loop[k]], m.vertices[face.loop[(k + 1) % n]], p);
      if ((p - q).squaredNorm() < bestSq) bestSq = (p - q).squaredNorm(), best = q;
    }
  }
  const double dist = std::sqrt(bestSq);
  return {best, (p - best) / dist, dist};
}

namespace {

double radiusOf(const Sphere& s) { return s.radius; }
double radiusOf(const Box& b) { return b.halfExtents.norm(); }
double radiusOf(const ConvexMesh& m) {
  double r = 0.0;
  for (const Vec3& v : m.vertices) r = std::max(r, v.norm());
  return r;
}
double radiusOf(const Compound& c) {
  double r = 0.0;
  for (const CompoundPart& part : c.parts)
    r = std::max(r, part.offset.norm() + partBoundingRadius(part.shape));
  return r;
}

Eigen::AlignedBox3d boundsOf(const Sphere& s, const Eigen::Quaterniond&) {
  return {Vec3::Constant(-s.radius), Vec3::Constant(s.radius)};
}
Eigen::AlignedBox3d boundsOf(const Box& b, const Eigen::Quaterniond& q) {
  const Vec3 extent = q.toRotationMatrix().cwiseAbs() * b.halfExtents;
  return {-extent, extent};
}
Eigen::AlignedBox3d boundsOf(const ConvexMesh& m, const Eigen::Quaterniond& q) {
  Eigen::AlignedBox3d box;
  for (const Vec3& v : m.vertices) box.extend(q * v);
  return box;
}
Eigen::AlignedBox3d boundsOf(const Compound& c, const Eigen::Quaterniond& q) {
  Eigen::AlignedBox3d box;
  for (const CompoundPart& part : c.parts) {
    const Eigen::AlignedBox3d b = std::visit([&](const auto& s) { return boundsOf(s, q * part.rotation); }, part.shape);
    const Vec3 shift = q * part.offset;
    box.extend(Eigen::AlignedBox3d(b.min() + shift, b.max() + shift));
  }
  return box;
}

template <class S>
double distanceOf(const S& s, const Vec3& p) {
  return closestSurfacePoint(s, p).distance;
}
// closestSurfacePoint(b, p).distance, bit for bit, without the point and normal (the distance of
// every particle near a paddle wheel to each of its blades, every granular step): outside, the
// distance to the clamped point; inside, the largest excess |p| - h over the axes.
double distanceOf(const Box& b, const Vec3& p) {
  const Vec3& h = b.halfExtents;
  const double outside = (p - p.cwiseMax(-h).cwiseMin(h)).squaredNorm();
  if (outside > 0.0) return std::sqrt(outside);
  return (p.cwiseAbs() - h).maxCoeff();
}
double distanceOf(const Compound& c, const Vec3& p) {
  double d = std::numeric_limits<double>::infinity();
  for (const CompoundPart& part : c.parts) {
    const Vec3 local = part.rotation.conjugate() * (p - part.offset);
    d = std::min(d, std::visit([&](const auto& s) { return distanceOf(s, local); }, part.shape));
  }
  return d;
}

}  // namespace

double partBoundingRadius(const PartShape& shape) {
  return std::visit([](const auto& s) { return radiusOf(s); }, shape);
}

double boundingRadius(const Shape& shape) {
  return std::visit([](const auto& s) { return radiusOf(s); }, shape);
}

Eigen::AlignedBox3d orientedBounds(const Shape& shape, const Eigen::Quaterniond& orientation) {
  return std::visit([&](const auto& s) { return boundsOf(s, orientation); }, shape);
}

double signedDistance(const Shape& shape, const Vec3& localPoint) {
  return std::visit([&](const auto& s) { return distanceOf(s, localPoint); }, shape);
}

}  // namespace msim::rigid
