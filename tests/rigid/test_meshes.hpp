#pragma once
// Closed outward-wound meshes with known mass properties, shared by the rigid tests.
#include "msim/core/triangle_mesh.hpp"

namespace msim::rigid::testing {

// Axis-aligned box [lo, hi] as 12 outward-wound triangles.
inline TriangleMesh boxMesh(const Vec3& lo, const Vec3& hi) {
  TriangleMesh m;
  for (int k = 0; k < 8; ++k)
    m.vertices.emplace_back((k & 1) ? hi.x() : lo.x(), (k & 2) ? hi.y() : lo.y(),
                            (k & 4) ? hi.z() : lo.z());
  // Faces as quads (outward normal by right-hand rule), split into two triangles each.
  const int quads[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                           {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  for (const auto& q : quads) {
    m.triangles.push_back({q[0], q[1], q[2]});
    m.triangles.push_back({q[0], q[2], q[3]});
  }
  return m;
}

// Tetrahedron (0,0,0), (1,0,0), (0,1,0), (0,0,1), scaled by s.
inline TriangleMesh tetrahedronMesh(double s = 1.0) {
  TriangleMesh m;
  m.vertices = {Vec3(0, 0, 0), Vec3(s, 0, 0), Vec3(0, s, 0), Vec3(0, 0, s)};
  m.triangles = {{0, 2, 1}, {0, 1, 3}, {0, 3, 2}, {1, 2, 3}};
  return m;
}

}  // namespace msim::rigid::testing
