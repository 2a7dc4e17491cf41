#pragma once
// Collision/mass shapes of a rigid body, in the body frame (origin at the centre of mass, so
// the generalized 6-vectors of Narain 2011 eq. 5.21-5.23 take moments about the body origin).
#include <array>
#include <variant>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::rigid {

struct Sphere {
  double radius = 0.5;
};

// Axis-aligned in the body frame; halfExtents are the half side lengths.
struct Box {
  Vec3 halfExtents{0.5, 0.5, 0.5};
};

// Closed, outward-wound triangle mesh. Built with makeConvexMesh (mass_properties.hpp), which
// validates it and moves the vertices so that the centre of mass is the body-frame origin.
struct ConvexMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

using Shape = std::variant<Sphere, Box, ConvexMesh>;

// Radius of the smallest origin-centred sphere holding the shape (broad phase bound).
double boundingRadius(const Shape& shape);

}  // namespace msim::rigid
