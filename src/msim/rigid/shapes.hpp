#pragma once
// Collision/mass shapes of a rigid body, in the body frame (origin at the centre of mass, so
// the generalized 6-vectors of Narain 2011 eq. 5.21-5.23 take moments about the body origin).
#include <array>
#include <variant>
#include <vector>

#include <Eigen/Geometry>

#include "msim/core/vec.hpp"

namespace msim::rigid {

struct Sphere {
  double radius = 0.5;
};

// Axis-aligned in the body frame; halfExtents are the half side lengths.
struct Box {
  Vec3 halfExtents{0.5, 0.5, 0.5};
};

// Planar convex polygon of a polyhedron: `loop` indexes the vertices counter-clockwise seen
// from outside; `normal . x = offset` on the face, `normal` pointing out.
struct ConvexFace {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
  std::vector<int> loop;
};

// Closed, outward-wound triangle mesh. Built with makeConvexMesh (mass_properties.hpp), which
// validates it, moves the vertices so that the centre of mass is the body-frame origin and fills
// the polygon faces. Contacts use faces and edges rather than triangles so that the diagonals of
// a flat face are neither separating axes nor clipping planes (a cube mesh collides like a Box).
struct ConvexMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
  std::vector<ConvexFace> faces;          // coplanar triangles merged
  std::vector<std::array<int, 2>> edges;  // polygon edges, each once
  std::vector<Vec3> edgeDirections;       // unit, one per parallel class (SAT axes)
};

// What a compound part may be: any shape but a compound (so the variant is not recursive).
using PartShape = std::variant<Sphere, Box, ConvexMesh>;

// A part of a compound: a non-compound shape placed in the compound frame by x = rotation *
// x_part + offset. Parts may overlap; contacts treat each part on its own.
struct CompoundPart {
  PartShape shape;
  Vec3 offset = Vec3::Zero();
  Eigen::Quaterniond rotation = Eigen::Quaterniond::Identity();
};

// Rigid union of parts (a paddle wheel: hub plus blades), non-convex as a whole. Built with
// makeCompound (mass_properties.hpp), which validates the parts and moves the offsets so that
// the centre of mass is the body-frame origin.
struct Compound {
  std::vector<CompoundPart> parts;
};

using Shape = std::variant<Sphere, Box, ConvexMesh, Compound>;

// Radius of the smallest origin-centred sphere holding the shape (broad phase bound).
double boundingRadius(const Shape& shape);
double partBoundingRadius(const PartShape& shape);

// Axis-aligned box holding the shape turned by `orientation`, in world axes relative to the body
// origin (exact for spheres, boxes and meshes; the union of the parts' for a compound). A long
// thin body's is much smaller than its bounding sphere's cube.
Eigen::AlignedBox3d orientedBounds(const Shape& shape, const Eigen::Quaterniond& orientation);

// Nearest surface point of a convex shape to a body-frame point: `distance` is signed (negative
// inside) and exact, `normal` the outward unit normal there (the gradient of the distance).
// Inside a polyhedron the nearest surface point lies on the nearest face plane.
struct SurfacePoint {
  Vec3 point = Vec3::Zero();
  Vec3 normal = Vec3::UnitZ();
  double distance = 0.0;
};
SurfacePoint closestSurfacePoint(const Sphere& sphere, const Vec3& localPoint);
SurfacePoint closestSurfacePoint(const Box& box, const Vec3& localPoint);
SurfacePoint closestSurfacePoint(const ConvexMesh& mesh, const Vec3& localPoint);

// Signed distance from the shape's surface to a body-frame point, negative inside. Exact for
// spheres, boxes and convex meshes. For a compound it is the minimum over the parts: exact
// outside, and inside never above the true value (overlapping parts make the union deeper than
// any one part), so the sign and the zero level set are right.
double signedDistance(const Shape& shape, const Vec3& localPoint);

}  // namespace msim::rigid
