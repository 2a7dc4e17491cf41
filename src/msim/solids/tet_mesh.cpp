#include "msim/solids/tet_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <map>
#include <set>
#include <stdexcept>
#include <string>
#include <unordered_map>
#include <utility>

#include <Eigen/Geometry>

namespace msim::solids {

double tetrahedronVolume6(const MassSpringSystem& system, const std::array<int, 4>& t) {
  const auto& x = system.x;
  return (x[t[1]] - x[t[0]]).cross(x[t[2]] - x[t[0]]).dot(x[t[3]] - x[t[0]]);
}

std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh) {
  // A positively oriented tetrahedron (a, b, c, d) has the outward faces (a, c, b), (a, b, d),
  // (a, d, c) and (b, c, d); a face shared by two tetrahedra is interior.
  std::map<std::array<int, 3>, std::pair<std::array<int, 3>, int>> faces;
  for (const auto& t : mesh.tetrahedra)
    for (const std::array<int, 3>& f : {std::array<int, 3>{t[0], t[2], t[1]}, std::array<int, 3>{t[0], t[1], t[3]},
                                        std::array<int, 3>{t[0], t[3], t[2]}, std::array<int, 3>{t[1], t[2], t[3]}}) {
      std::array<int, 3> key = f;
      std::sort(key.begin(), key.end());
      auto& entry = faces[key];
      entry.first = f;
      ++entry.second;
    }
  std::vector<std::array<int, 3>> out;
  for (const auto& [key, entry] : faces)
    if (entry.second == 1) out.push_back(entry.first);
  return out;
}

TetMesh bccTetMesh(const geometry::Shape3& shape, double spacing) {
  if (!(spacing > 0.0)) throw std::invalid_argument("BCC tetrahedra: the spacing must be > 0");
  const geometry::Bounds<3> box = shape.bounds();
  if (!box.min.allFinite() || !box.max.allFinite()) throw std::invalid_argument("BCC tetrahedra: the shape must be bounded");
  const Vec3 origin = box.min - Vec3::Constant(spacing);
  IVec3 cells;
  for (int a = 0; a < 3; ++a) cells[a] = static_cast<int>(std::ceil((box.max[a] - box.min[a]) / spacing)) + 2;
  if (double(cells[0] + 1) * double(cells[1] + 1) * double(cells[2] + 1) * 2.0 > 2147483647.0)
    throw std::invalid_argument("BCC tetrahedra: the lattice is too large for the spacing");
  // Lattice node ids: corners (i, j, k) and centres of cell (i, j, k); mesh vertices made on use.
  auto cornerKey = [&](int i, int j, int k) { return (static_cast<long long>(k) * (cells[1] + 1) + j) * (cells[0] + 1) + i; };
  const long long centreBase = static_cast<long long>(cells[0] + 1) * (cells[1] + 1) * (cells[2] + 1);
  auto centreKey = [&](int i, int j, int k) { return centreBase + (static_cast<long long>(k) * cells[1] + j) * cells[0] + i; };
  auto cornerAt = [&](int i, int j, int k) { return Vec3(origin + spacing * Vec3(i, j, k)); };
  auto centreAt = [&](int i, int j, int k) { return Vec3(origin + spacing * Vec3(i + 0.5, j + 0.5, k + 0.5)); };
  TetMesh mesh;
  std::unordered_map<long long, int> index;
  auto vertex = [&](long long key, const Vec3& at) {
    const auto [it, added] = index.emplace(key, static_cast<int>(mesh.vertices.size()));
    if (added) mesh.vertices.push_back(at);
    return it->second;
  };
  // The face between cell c and its neighbour c + e_a: the face's corners in cyclic order.
  for (int k = 0; k < cells[2]; ++k)
    for (int j = 0; j < cells[1]; ++j)
      for (int i = 0; i < cells[0]; ++i)
        for (int a = 0; a < 3; ++a) {
          IVec3 next(i, j, k);
          next[a] += 1;
          if (next[a] >= cells[a]) continue;
          // Corners of the shared face (at coordinate next[a] along a), cyclic in the other axes.
          const int b = (a + 1) % 3, c = (a + 2) % 3;
          std::array<IVec3, 4> face;
          for (int q = 0; q < 4; ++q) {
            IVec3 corner = next;
            corner[b] = IVec3(i, j, k)[b] + ((q == 1 || q == 2) ? 1 : 0);
            corner[c] = IVec3(i, j, k)[c] + ((q == 2 || q == 3) ? 1 : 0);
            face[static_cast<std::size_t>(q)] = corner;
          }
          const Vec3 p = centreAt(i, j, k), q = centreAt(next[0], next[1], next[2]);
          for (int e = 0; e < 4; ++e) {
            const IVec3 r = face[static_cast<std::size_t>(e)], s = face[static_cast<std::size_t>((e + 1) % 4)];
            const Vec3 xr = cornerAt(r[0], r[1], r[2]), xs = cornerAt(s[0], s[1], s[2]);
            if (!(shape.distance(0.25 * (p + q + xr + xs)) < 0.0)) continue;
            std::array<int, 4> t = {vertex(centreKey(i, j, k), p), vertex(centreKey(next[0], next[1], next[2]), q),
                                    vertex(cornerKey(r[0], r[1], r[2]), xr), vertex(cornerKey(s[0], s[1], s[2]), xs)};
            const Vec3& x0 = mesh.vertices[t[0]];
            if ((mesh.vertices[t[1]] - x0).cross(mesh.vertices[t[2]] - x0).dot(mesh.vertices[t[3]] - x0) < 0.0)
              std::swap(t[2], t[3]);
            mesh.tetrahedra.push_back(t);
          }
        }
  return mesh;
}

MassSpringSystem solidSystem(const TetMesh& mesh, const SolidMaterial& material) {
  if (!(material.density > 0.0) || !(material.edgeStiffness > 0.0) || !(material.altitudeStiffness >= 0.0) ||
      !(material.edgeDamping >= 0.0) || !(material.altitudeDamping >= 0.0))
    throw std::invalid_argument("solid: density and edge stiffness must be > 0, altitude stiffness and damping >= 0");
  MassSpringSystem system;
  std::vector<double> mass(mesh.vertices.size(), 0.0);
  std::set<std::pair<int, int>> edges;
  const int n = static_cast<int>(mesh.vertices.size());
  for (std::size_t t = 0; t < mesh.tetrahedra.size(); ++t) {
    const auto& tet = mesh.tetrahedra[t];
    for (const int v : tet)
      if (v < 0 || v >= n) throw std::invalid_argument("solid: tetrahedron " + std::to_string(t) + " names a vertex out of range");
    const Vec3& x0 = mesh.vertices[tet[0]];
    const double v6 = (mesh.vertices[tet[1]] - x0).cross(mesh.vertices[tet[2]] - x0).dot(mesh.vertices[tet[3]] - x0);
    if (!(v6 > 0.0)) throw std::invalid_argument("solid: tetrahedron " + std::to_string(t) + " is inverted or flat at rest");
    for (const int v : tet) mass[static_cast<std::size_t>(v)] += material.density * v6 / 24.0;
    for (int a = 0; a < 4; ++a)
      for (int b = a + 1; b < 4; ++b) edges.insert({std::min(tet[a], tet[b]), std::max(tet[a], tet[b])});
  }
  for (std::size_t v = 0; v < mesh.vertices.size(); ++v) {
    if (!(mass[v] > 0.0)) throw std::invalid_argument("solid: vertex " + std::to_string(v) + " belongs to no tetrahedron");
    system.addParticle(mesh.vertices[v], mass[v]);
  }
  for (const auto& [a, b] : edges) system.addSpring(a, b, material.edgeStiffness, material.edgeDamping);
  if (material.altitudeStiffness > 0.0 || material.altitudeDamping > 0.0)
    for (const auto& tet : mesh.tetrahedra) system.addTetrahedron(tet, material.altitudeStiffness, material.altitudeDamping);
  return system;
}

}  // namespace msim::solids
