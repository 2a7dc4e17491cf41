#pragma once
// Narrow-phase contact generation. A Contact joins body a to body b (b = kWorld for a domain
// plane); `normal` is the unit normal pointing from b towards a, `depth` the penetration
// (negative: separated by -depth, kept as a speculative contact within the margin).
// Pairs handled: sphere-sphere, sphere-box, and any shape against a plane (a sphere by its
// centre, a box or mesh by its vertices, which is exact for flat faces resting on the plane).
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
// Appends at most one contact between bodies ia and ib if their shapes are a handled pair;
// returns false for an unhandled pair (box-box, mesh-anything).
bool collidePair(const RigidBody& A, int ia, const RigidBody& B, int ib, double margin,
                 std::vector<Contact>& out);

// The six inward-facing walls of the axis-aligned box [lo, hi].
std::vector<Plane> domainWalls(const Vec3& lo, const Vec3& hi, const Material& material = {});

}  // namespace msim::rigid
