#pragma once
// Narrow-phase contact generation. A Contact joins body a to body b (b = kWorld for a domain
// plane); `normal` is the unit normal pointing from b towards a, `depth` the penetration
// (negative: separated by -depth, kept as a speculative contact within the margin).
// Every pair of shapes is handled. A compound collides part by part (each part against the other
// body's parts or the plane), so a contact's point and normal come from one convex part:
//   * sphere against anything: the nearest surface point of the other part to the centre
//     (inside a box or mesh: through the least-deep face), one contact;
//   * box/mesh against box/mesh: separating axis test and clipped contact manifold, up to 4
//     contacts (polyhedron_contact.hpp);
//   * against a plane: a sphere by its centre, a box or mesh by its vertices (exact for faces
//     resting flat on the plane).
#include <vector>

#include "msim/rigid/rigid_body.hpp"

namespace msim::rigid {

inline constexpr int kWorld = -1;

// Half space n . x >= offset is free space (n unit, pointing into the domain).
struct Plane {
  Vec3 normal = Vec3::UnitZ();
  double offset = 0.0;
  Material material;
};

struct Contact {
  int a = 0;
  int b = kWorld;
  Vec3 point = Vec3::Zero();   // world contact point (on the surface of b)
  Vec3 normal = Vec3::UnitZ();
  double depth = 0.0;
  double friction = 0.0;     // pair Coulomb coefficient, filled in by World
  double restitution = 0.0;  // pair restitution, filled in by World
};

// Appends the contacts of body `a` with the plane whose penetration exceeds -margin.
void collidePlane(const RigidBody& body, int a, const Plane& plane, double margin,
                  std::vector<Contact>& out);
// Appends the contacts between bodies ia and ib whose penetration exceeds -margin (several for
// polyhedra and compounds). A contact's `a` may be ib when ib's part is the sphere of the pair.
void collidePair(const RigidBody& A, int ia, const RigidBody& B, int ib, double margin,
                 std::vector<Contact>& out);

// The six inward-facing walls of the axis-aligned box [lo, hi].
std::vector<Plane> domainWalls(const Vec3& lo, const Vec3& hi, const Material& material = {});

}  // namespace msim::rigid
