#pragma once
// A triangle mesh in world units: shared vertex positions and index triples.
#include <array>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::geometry {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

}  // namespace msim::geometry
