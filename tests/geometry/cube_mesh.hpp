#pragma once
// The unit cube [0,1]^3 as 12 outward-wound triangles, shared by the mesh tests.
#include "msim/core/triangle_mesh.hpp"

namespace msim::geometry::testing {

inline TriangleMesh unitCubeMesh() {
  TriangleMesh m;
  for (int i = 0; i < 8; ++i) m.vertices.emplace_back(i & 1, (i >> 1) & 1, (i >> 2) & 1);  // vertex i = bits (x,y,z)
  m.triangles = {{0, 2, 3}, {0, 3, 1},   // z = 0, normal -z
                 {4, 5, 7}, {4, 7, 6},   // z = 1, normal +z
                 {0, 1, 5}, {0, 5, 4},   // y = 0, normal -y
                 {2, 6, 7}, {2, 7, 3},   // y = 1, normal +y
                 {0, 4, 6}, {0, 6, 2},   // x = 0, normal -x
                 {1, 3, 7}, {1, 7, 5}};  // x = 1, normal +x
  return m;
}

}  // namespace msim::geometry::testing
