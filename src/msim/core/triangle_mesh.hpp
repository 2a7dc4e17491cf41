#pragma once
// A triangle mesh in world units: shared vertex positions and index triples. A core type, so
// io (which reads and writes meshes) and geometry (which measures them) need not include each other.
#include <array>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim {

struct TriangleMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 3>> triangles;
};

}  // namespace msim
