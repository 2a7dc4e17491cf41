#include "msim/rigid/collision.hpp"

#include <algorithm>
#include <cmath>

namespace msim::rigid {
namespace {

void sphereSphere(const RigidBody& A, int ia, double ra, const RigidBody& B, int ib, double rb,
                  double margin, std::vector<Contact>& out) {
  const Vec3 d = A.position - B.position;
  const double dist = d.norm();
  const double depth = ra + rb - dist;
  if (depth < -margin) return;
  // Coincident centres: any normal is right; pick +z so the result is deterministic.
  const Vec3 n = dist > 0.0 ? Vec3(d / dist) : Vec3(Vec3::UnitZ());
  out.push_back({ia, ib, B.position + n * rb, n, depth, 0.0, 0.0});
}

// Sphere (a) against box (b): closest point of the box to the centre; if the centre is inside,
// push out through the nearest face.
void sphereBox(const RigidBody& S, int is, double r, const RigidBody& B, int ib, const Vec3& h,
               double margin, std::vector<Contact>& out) {
  const Eigen::Matrix3d R = B.rotation();
  const Vec3 c = R.transpose() * (S.position - B.position);  // sphere centre in box frame
  const Vec3 q = c.cwiseMax(-h).cwiseMin(h);
  Vec3 nLocal;
  double depth;
  Vec3 surface;
  if ((c - q).squaredNorm() > 0.0) {
    const double dist = (c - q).norm();
    nLocal = (c - q) / dist;
    depth = r - dist;
    surface = q;
  } else {
    int axis = 0;
    double best = h[0] - std::abs(c[0]);
    for (int k = 1; k < 3; ++k)
      if (h[k] - std::abs(c[k]) < best) best = h[k] - std::abs(c[k]), axis = k;
    nLocal = Vec3::Zero();
    nLocal[axis] = c[axis] >= 0.0 ? 1.0 : -1.0;
    depth = r + best;
    surface = c;
    surface[axis] = nLocal[axis] * h[axis];
  }
  if (depth < -margin) return;
  out.push_back({is, ib, B.position + R * surface, R * nLocal, depth, 0.0, 0.0});
}

}  // namespace

void collidePlane(const RigidBody& body, int a, const Plane& plane, double margin,
                  std::vector<Contact>& out) {
  auto add = [&](const Vec3& p, double extra) {
    const double depth = plane.offset - plane.normal.dot(p) + extra;
    if (depth >= -margin)
      out.push_back({a, kWorld, p - plane.normal * (plane.normal.dot(p) - plane.offset),
                     plane.normal, depth, 0.0, 0.0});
  };
  if (const auto* s = std::get_if<Sphere>(&body.shape())) {
    add(body.position, s->radius);
  } else if (const auto* b = std::get_if<Box>(&body.shape())) {
    for (int k = 0; k < 8; ++k) {
      const Vec3 corner((k & 1) ? b->halfExtents.x() : -b->halfExtents.x(),
                        (k & 2) ? b->halfExtents.y() : -b->halfExtents.y(),
                        (k & 4) ? b->halfExtents.z() : -b->halfExtents.z());
      add(body.toWorld(corner), 0.0);
    }
  } else {
    for (const Vec3& v : std::get<ConvexMesh>(body.shape()).vertices) add(body.toWorld(v), 0.0);
  }
}

bool collidePair(const RigidBody& A, int ia, const RigidBody& B, int ib, double margin,
                 std::vector<Contact>& out) {
  const auto* sa = std::get_if<Sphere>(&A.shape());
  const auto* sb = std::get_if<Sphere>(&B.shape());
  if (sa && sb) {
    sphereSphere(A, ia, sa->radius, B, ib, sb->radius, margin, out);
    return true;
  }
  if (sa) {
    if (const auto* bb = std::get_if<Box>(&B.shape())) {
      sphereBox(A, ia, sa->radius, B, ib, bb->halfExtents, margin, out);
      return true;
    }
  }
  if (sb) {
    if (const auto* ba = std::get_if<Box>(&A.shape())) {
      sphereBox(B, ib, sb->radius, A, ia, ba->halfExtents, margin, out);
      return true;
    }
  }
  return false;
}

std::vector<Plane> domainWalls(const Vec3& lo, const Vec3& hi, const Material& material) {
  std::vector<Plane> walls;
  for (int k = 0; k < 3; ++k) {
    Vec3 n = Vec3::Zero();
    n[k] = 1.0;
    walls.push_back({n, lo[k], material});
    walls.push_back({-n, -hi[k], material});
  }
  return walls;
}

}  // namespace msim::rigid
