#include "msim/rigid/collision.hpp"

#include <variant>

#include "msim/rigid/polyhedron.hpp"
#include "msim/rigid/polyhedron_contact.hpp"

namespace msim::rigid {
namespace {

// A convex part of a body, placed in the world.
struct PosedPart {
  std::variant<const Sphere*, const Box*, const ConvexMesh*> shape;
  Pose pose;
  double radius;  // bounding radius about pose.position
};

template <class S>
void addParts(const S& shape, const Pose& pose, double radius, std::vector<PosedPart>& parts) {
  parts.push_back({&shape, pose, radius});
}

void addParts(const Compound& compound, const Pose& pose, double, std::vector<PosedPart>& parts) {
  for (const CompoundPart& part : compound.parts)
    std::visit(
        [&](const auto& s) {
          parts.push_back({&s,
                           Pose{pose.toWorld(part.offset),
                                pose.rotation * part.rotation.toRotationMatrix()},
                           partBoundingRadius(part.shape)});
        },
        part.shape);
}

std::vector<PosedPart> posedParts(const RigidBody& body) {
  std::vector<PosedPart> parts;
  const Pose pose{body.position, body.rotation()};
  const double radius = boundingRadius(body.shape());
  std::visit([&](const auto& s) { addParts(s, pose, radius, parts); }, body.shape());
  return parts;
}

void planeContacts(const Sphere& s, const Pose& pose, auto&& add) { add(pose.position, s.radius); }
void planeContacts(const Box& b, const Pose& pose, auto&& add) {
  for (const Vec3& v : boxPolyhedron(b.halfExtents).vertices) add(pose.toWorld(v), 0.0);
}
void planeContacts(const ConvexMesh& m, const Pose& pose, auto&& add) {
  for (const Vec3& v : m.vertices) add(pose.toWorld(v), 0.0);
}

// Sphere (centre, radius r, body is) against a part of body io.
void spherePart(const Vec3& centre, double r, int is, const PosedPart& other, int io,
                double margin, std::vector<Contact>& out) {
  const Vec3 local = other.pose.rotation.transpose() * (centre - other.pose.position);
  const SurfacePoint s =
      std::visit([&](const auto* shape) { return closestSurfacePoint(*shape, local); }, other.shape);
  const double depth = r - s.distance;
  if (depth < -margin) return;
  out.push_back({is, io, other.pose.toWorld(s.point), other.pose.rotation * s.normal, depth, 0.0,
                 0.0});
}

// Boxes become polyhedra in `storage`; meshes are used as they are.
const ConvexMesh& polyhedronOf(const PosedPart& part, ConvexMesh& storage) {
  if (const auto* box = std::get_if<const Box*>(&part.shape)) {
    storage = boxPolyhedron((*box)->halfExtents);
    return storage;
  }
  return *std::get<const ConvexMesh*>(part.shape);
}

void collideParts(const PosedPart& pa, int ia, const PosedPart& pb, int ib, double margin,
                  std::vector<Contact>& out) {
  if (const auto* s = std::get_if<const Sphere*>(&pa.shape))
    return spherePart(pa.pose.position, (*s)->radius, ia, pb, ib, margin, out);
  if (const auto* s = std::get_if<const Sphere*>(&pb.shape))
    return spherePart(pb.pose.position, (*s)->radius, ib, pa, ia, margin, out);
  ConvexMesh boxA, boxB;
  collidePolyhedra(polyhedronOf(pa, boxA), pa.pose, ia, polyhedronOf(pb, boxB), pb.pose, ib,
                   margin, out);
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
  for (const PosedPart& part : posedParts(body))
    std::visit([&](const auto* shape) { planeContacts(*shape, part.pose, add); }, part.shape);
}

void collidePair(const RigidBody& A, int ia, const RigidBody& B, int ib, double margin,
                 std::vector<Contact>& out) {
  const std::vector<PosedPart> partsA = posedParts(A), partsB = posedParts(B);
  for (const PosedPart& pa : partsA)
    for (const PosedPart& pb : partsB) {
      const double reach = pa.radius + pb.radius + 2.0 * margin;
      if ((pa.pose.position - pb.pose.position).squaredNorm() > reach * reach) continue;
      collideParts(pa, ia, pb, ib, margin, out);
    }
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
