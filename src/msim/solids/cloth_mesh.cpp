#include "msim/solids/cloth_mesh.hpp"

#include <algorithm>
#include <map>
#include <stdexcept>
#include <string>
#include <utility>

#include <Eigen/Geometry>

namespace msim::solids {

TriangleMesh clothPatch(const Vec3& origin, const Vec3& edgeU, const Vec3& edgeV, int nu, int nv) {
  if (nu < 1 || nv < 1) throw std::invalid_argument("cloth patch: at least one quad along each side");
  if (!(edgeU.cross(edgeV).norm() > 0.0)) throw std::invalid_argument("cloth patch: the two edges are parallel");
  TriangleMesh mesh;
  for (int j = 0; j <= nv; ++j)
    for (int i = 0; i <= nu; ++i) mesh.vertices.push_back(origin + (double(i) / nu) * edgeU + (double(j) / nv) * edgeV);
  auto at = [&](int i, int j) { return j * (nu + 1) + i; };
  for (int j = 0; j < nv; ++j)
    for (int i = 0; i < nu; ++i) {
      const int a = at(i, j), b = at(i + 1, j), c = at(i + 1, j + 1), d = at(i, j + 1);
      if (i % 2 == 0) {  // diagonal a-c
        mesh.triangles.push_back({a, b, c});
        mesh.triangles.push_back({a, c, d});
      } else {  // diagonal b-d
        mesh.triangles.push_back({a, b, d});
        mesh.triangles.push_back({b, c, d});
      }
    }
  return mesh;
}

MassSpringSystem clothSystem(const TriangleMesh& mesh, const ClothMaterial& material) {
  if (!(material.arealDensity > 0.0) || !(material.edgeStiffness > 0.0) || !(material.bendStiffness >= 0.0) ||
      !(material.edgeDamping >= 0.0) || !(material.bendDamping >= 0.0))
    throw std::invalid_argument("cloth: density and edge stiffness must be > 0, bending stiffness and damping >= 0");
  const int n = static_cast<int>(mesh.vertices.size());
  std::vector<double> mass(mesh.vertices.size(), 0.0);
  // Each edge (smaller index first) with the vertices opposite it in its triangles.
  std::map<std::pair<int, int>, std::vector<int>> opposite;
  for (std::size_t t = 0; t < mesh.triangles.size(); ++t) {
    const auto& tri = mesh.triangles[t];
    for (const int v : tri)
      if (v < 0 || v >= n) throw std::invalid_argument("cloth: triangle " + std::to_string(t) + " names a vertex out of range");
    const Vec3 a = mesh.vertices[tri[0]], b = mesh.vertices[tri[1]], c = mesh.vertices[tri[2]];
    const double area = 0.5 * (b - a).cross(c - a).norm();
    if (!(area > 0.0)) throw std::invalid_argument("cloth: triangle " + std::to_string(t) + " is degenerate");
    for (const int v : tri) mass[static_cast<std::size_t>(v)] += material.arealDensity * area / 3.0;
    for (int k = 0; k < 3; ++k) {
      const int p = tri[k], q = tri[(k + 1) % 3];
      auto& list = opposite[{std::min(p, q), std::max(p, q)}];
      list.push_back(tri[(k + 2) % 3]);
      if (list.size() > 2)
        throw std::invalid_argument("cloth: edge " + std::to_string(p) + "-" + std::to_string(q) +
                                    " is shared by more than two triangles (not a manifold)");
    }
  }
  MassSpringSystem system;
  for (int v = 0; v < n; ++v) {
    if (!(mass[static_cast<std::size_t>(v)] > 0.0))
      throw std::invalid_argument("cloth: vertex " + std::to_string(v) + " belongs to no triangle");
    system.addParticle(mesh.vertices[static_cast<std::size_t>(v)], mass[static_cast<std::size_t>(v)]);
  }
  for (const auto& [edge, across] : opposite) {
    system.addSpring(edge.first, edge.second, material.edgeStiffness, material.edgeDamping);
    if (across.size() == 2 && material.bendStiffness > 0.0)
      system.addSpring(across[0], across[1], material.bendStiffness, material.bendDamping);
  }
  return system;
}

}  // namespace msim::solids
