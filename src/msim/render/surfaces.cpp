#include "msim/render/surfaces.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>  // cross products

namespace msim::render {

namespace {

bool unitInterval(const Vec3& c) { return c.allFinite() && (c.array() >= 0.0).all() && (c.array() <= 1.0).all(); }

// Moller-Trumbore ray-triangle intersection: t, and the barycentric weights (u, v) of b and c.
bool intersectTriangle(const Vec3& o, const Vec3& d, const Vec3& a, const Vec3& b, const Vec3& c, double& t, double& u,
                       double& v) {
  const Vec3 e1 = b - a, e2 = c - a;
  const Vec3 p = d.cross(e2);
  const double det = e1.dot(p);
  if (std::abs(det) < 1e-300) return false;  // ray parallel to the triangle's plane
  const double inv = 1.0 / det;
  const Vec3 s = o - a;
  u = s.dot(p) * inv;
  if (u < 0.0 || u > 1.0) return false;
  const Vec3 q = s.cross(e1);
  v = d.dot(q) * inv;
  if (v < 0.0 || u + v > 1.0) return false;
  t = e2.dot(q) * inv;
  return true;
}

// Nearest root t > 0 of |o + t d - c| = r (d unit length).
bool intersectSphere(const Vec3& o, const Vec3& d, const Vec3& c, double r, double& t) {
  const Vec3 oc = o - c;
  const double b = oc.dot(d), disc = b * b - (oc.squaredNorm() - r * r);
  if (disc < 0.0) return false;
  const double s = std::sqrt(disc);
  t = -b - s > 0.0 ? -b - s : -b + s;
  return t > 0.0;
}

void checkMesh(const TriangleMesh& m, std::size_t index) {
  const int n = static_cast<int>(m.vertices.size());
  for (const Vec3& v : m.vertices)
    if (!v.allFinite()) throw std::invalid_argument("surfaces: mesh " + std::to_string(index) + " has a non-finite vertex");
  for (const auto& tri : m.triangles)
    for (int k : tri)
      if (k < 0 || k >= n)
        throw std::invalid_argument("surfaces: mesh " + std::to_string(index) + " has a triangle with vertex index " +
                                    std::to_string(k) + " (it has " + std::to_string(n) + " vertices)");
}

}  // namespace

void PointSet::validate() const {
  if (!positions) throw std::invalid_argument("point set: positions are required (got null)");
  if (!std::isfinite(radius) || !(radius > 0.0))
    throw std::invalid_argument("point set: radius must be positive, got " + std::to_string(radius));
  if (colours && colours->size() != positions->size())
    throw std::invalid_argument("point set: " + std::to_string(colours->size()) + " colours for " +
                                std::to_string(positions->size()) + " points");
  if (!unitInterval(albedo)) throw std::invalid_argument("point set: albedo must be in [0, 1]");
}

SurfaceScene::SurfaceScene(const std::vector<const TriangleMesh*>& meshes, const std::vector<PointSet>& points,
                           const Vec3& meshAlbedo)
    : meshes_(meshes), points_(points), meshAlbedo_(meshAlbedo) {
  std::vector<numerics::Aabb> boxes;
  for (std::size_t m = 0; m < meshes_.size(); ++m) {
    if (!meshes_[m]) throw std::invalid_argument("surfaces: mesh " + std::to_string(m) + " is null");
    const TriangleMesh& mesh = *meshes_[m];
    checkMesh(mesh, m);
    // Area-weighted vertex normals (the cross product's length is twice the area), oriented by the
    // winding; hits flip them to the ray's side, so the winding need not be consistent.
    std::vector<Vec3> normals(mesh.vertices.size(), Vec3::Zero());
    for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
      const auto& [a, b, c] = mesh.triangles[t];
      const Vec3& va = mesh.vertices[static_cast<std::size_t>(a)];
      const Vec3 n = (mesh.vertices[static_cast<std::size_t>(b)] - va).cross(mesh.vertices[static_cast<std::size_t>(c)] - va);
      numerics::Aabb box;
      for (int k : mesh.triangles[t]) {
        normals[static_cast<std::size_t>(k)] += n;
        box.grow(mesh.vertices[static_cast<std::size_t>(k)]);
      }
      boxes.push_back(box);
      primitives_.push_back({static_cast<int>(m), static_cast<int>(t), false});
    }
    for (Vec3& n : normals)
      if (n.norm() > 0.0) n.normalize();
    vertexNormals_.push_back(std::move(normals));
  }
  for (std::size_t s = 0; s < points_.size(); ++s) {
    try {
      points_[s].validate();
    } catch (const std::invalid_argument& e) {
      throw std::invalid_argument("surfaces: point set " + std::to_string(s) + ": " + e.what());
    }
    const auto& pos = *points_[s].positions;
    const Vec3 r = Vec3::Constant(points_[s].radius);
    for (std::size_t i = 0; i < pos.size(); ++i) {
      const Vec3 c = pos[i].cast<double>();
      if (!c.allFinite()) throw std::invalid_argument("surfaces: point set " + std::to_string(s) + " has a non-finite position");
      boxes.push_back({c - r, c + r});
      primitives_.push_back({static_cast<int>(s), static_cast<int>(i), true});
    }
  }
  bvh_ = numerics::Bvh(boxes);
}

bool SurfaceScene::hitPrimitive(const Primitive& p, const Vec3& o, const Vec3& d, double& tMax, SurfaceHit* hit) const {
  if (p.sphere) {
    const PointSet& set = points_[static_cast<std::size_t>(p.set)];
    const Vec3 c = (*set.positions)[static_cast<std::size_t>(p.index)].cast<double>();
    double t;
    if (!intersectSphere(o, d, c, set.radius, t) || !(t < tMax)) return false;
    tMax = t;
    if (hit) {
      Vec3 n = (o + t * d - c) / set.radius;
      if (n.dot(d) > 0.0) n = -n;  // a ray from inside the sphere sees its inner face
      hit->t = t;
      hit->normal = hit->offsetNormal = n;
      hit->albedo = set.colours ? Vec3((*set.colours)[static_cast<std::size_t>(p.index)].cast<double>()) : set.albedo;
    }
    return true;
  }
  const TriangleMesh& mesh = *meshes_[static_cast<std::size_t>(p.set)];
  const auto& [ia, ib, ic] = mesh.triangles[static_cast<std::size_t>(p.index)];
  const Vec3& a = mesh.vertices[static_cast<std::size_t>(ia)];
  const Vec3& b = mesh.vertices[static_cast<std::size_t>(ib)];
  const Vec3& c = mesh.vertices[static_cast<std::size_t>(ic)];
  double t, u, v;
  if (!intersectTriangle(o, d, a, b, c, t, u, v) || !(t > 0.0 && t < tMax)) return false;
  tMax = t;
  if (hit) {
    const std::vector<Vec3>& vn = vertexNormals_[static_cast<std::size_t>(p.set)];
    Vec3 geometric = (b - a).cross(c - a).normalized();
    if (geometric.dot(d) > 0.0) geometric = -geometric;
    Vec3 n = (1.0 - u - v) * vn[static_cast<std::size_t>(ia)] + u * vn[static_cast<std::size_t>(ib)] +
             v * vn[static_cast<std::size_t>(ic)];
    n = n.norm() > 0.0 ? Vec3(n.normalized()) : geometric;
    if (n.dot(geometric) < 0.0) n = -n;
    hit->t = t;
    hit->normal = n;
    hit->offsetNormal = geometric;
    hit->albedo = meshAlbedo_;
  }
  return true;
}

bool SurfaceScene::intersect(const Ray& ray, double tMax, SurfaceHit& hit) const {
  return bvh_.traverse<false>(ray.origin, ray.direction, tMax, [&](int p, double& t) {
    return hitPrimitive(primitives_[static_cast<std::size_t>(p)], ray.origin, ray.direction, t, &hit);
  });
}

bool SurfaceScene::occluded(const Vec3& origin, const Vec3& dir, double tMax) const {
  return bvh_.traverse<true>(origin, dir, tMax, [&](int p, double& t) {
    return hitPrimitive(primitives_[static_cast<std::size_t>(p)], origin, dir, t, nullptr);
  });
}

int meshContaining(const std::vector<const TriangleMesh*>& meshes, const Vec3& x, int* crossings) {
  // An irrational-looking direction, so that the ray does not run along the edges or faces of
  // axis-aligned meshes (a hit on a shared edge would count twice).
  const Vec3 dir = Vec3(0.3141, 0.5772, 0.7548).normalized();
  for (std::size_t m = 0; m < meshes.size(); ++m) {
    if (!meshes[m]) throw std::invalid_argument("surfaces: mesh " + std::to_string(m) + " is null");
    const TriangleMesh& mesh = *meshes[m];
    checkMesh(mesh, m);
    int count = 0;
    for (const auto& [a, b, c] : mesh.triangles) {
      double t, u, v;
      if (intersectTriangle(x, dir, mesh.vertices[static_cast<std::size_t>(a)], mesh.vertices[static_cast<std::size_t>(b)],
                            mesh.vertices[static_cast<std::size_t>(c)], t, u, v) &&
          t > 0.0)
        ++count;
    }
    if (count % 2 == 1) {
      if (crossings) *crossings = count;
      return static_cast<int>(m);
    }
  }
  if (crossings) *crossings = 0;
  return -1;
}

}  // namespace msim::render
