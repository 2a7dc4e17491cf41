#include "msim/rigid/polyhedron.hpp"

#include <algorithm>
#include <cmath>
#include <set>
#include <utility>

namespace msim::rigid {
namespace {

// Two unit face normals closer than ~1e-4 rad are one face: enough for meshes written in single
// precision, far below any real facet angle.
constexpr double kCoplanarCos = 1.0 - 5e-9;

// Counter-clockwise convex hull (Andrew's monotone chain) of the vertices `ids` projected onto
// the plane spanned by (u, w); collinear points are dropped.
std::vector<int> hullLoop(const std::vector<Vec3>& vertices, std::vector<int> ids, const Vec3& u,
                          const Vec3& w) {
  auto uv = [&](int i) { return Eigen::Vector2d(vertices[i].dot(u), vertices[i].dot(w)); };
  std::sort(ids.begin(), ids.end(), [&](int a, int b) {
    const Eigen::Vector2d pa = uv(a), pb = uv(b);
    return pa.x() < pb.x() || (pa.x() == pb.x() && pa.y() < pb.y());
  });
  auto turn = [&](int o, int a, int b) {
    const Eigen::Vector2d p = uv(a) - uv(o), q = uv(b) - uv(o);
    return p.x() * q.y() - p.y() * q.x();
  };
  std::vector<int> loop;
  for (int pass = 0; pass < 2; ++pass) {
    const std::size_t start = loop.size();
    for (int id : ids) {
      while (loop.size() >= start + 2 && turn(loop[loop.size() - 2], loop.back(), id) <= 0.0)
        loop.pop_back();
      loop.push_back(id);
    }
    loop.pop_back();  // the first point of the other chain
    std::reverse(ids.begin(), ids.end());
  }
  return loop;
}

void addEdgeDirection(std::vector<Vec3>& directions, const Vec3& d) {
  for (const Vec3& e : directions)
    if (e.cross(d).norm() < kParallelSine) return;
  directions.push_back(d);
}

}  // namespace

void buildConvexFeatures(ConvexMesh& mesh) {
  double extent = 0.0;
  for (const Vec3& v : mesh.vertices) extent = std::max(extent, v.norm());
  const double planeTol = 1e-7 * extent;
  std::vector<std::vector<int>> faceVertices;
  std::vector<Vec3> areaNormals;  // summed area-weighted normals of the merged triangles
  mesh.faces.clear();
  for (const auto& tri : mesh.triangles) {
    const Vec3& p0 = mesh.vertices[tri[0]];
    const Vec3 areaNormal = (mesh.vertices[tri[1]] - p0).cross(mesh.vertices[tri[2]] - p0);
    if (!(areaNormal.norm() > 1e-14 * extent * extent)) continue;  // sliver: no plane of its own
    const Vec3 n = areaNormal.normalized();
    std::size_t f = 0;
    for (; f < mesh.faces.size(); ++f)
      if (mesh.faces[f].normal.dot(n) > kCoplanarCos &&
          std::abs(mesh.faces[f].offset - n.dot(p0)) <= planeTol)
        break;
    if (f == mesh.faces.size()) {
      mesh.faces.push_back({n, n.dot(p0), {}});
      faceVertices.emplace_back();
      areaNormals.push_back(Vec3::Zero());
    }
    areaNormals[f] += areaNormal;
    faceVertices[f].insert(faceVertices[f].end(), tri.begin(), tri.end());
  }
  std::set<std::pair<int, int>> edges;
  for (std::size_t f = 0; f < mesh.faces.size(); ++f) {
    ConvexFace& face = mesh.faces[f];
    std::vector<int>& ids = faceVertices[f];
    std::sort(ids.begin(), ids.end());
    ids.erase(std::unique(ids.begin(), ids.end()), ids.end());
    face.normal = areaNormals[f].normalized();
    // Any unit u in the plane; w = n x u makes (u, w) counter-clockwise seen from outside.
    const Vec3 helper = std::abs(face.normal.x()) < 0.57 ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
    const Vec3 u = face.normal.cross(helper).normalized();
    face.loop = hullLoop(mesh.vertices, ids, u, face.normal.cross(u));
    face.offset = 0.0;
    for (int i : face.loop) face.offset += face.normal.dot(mesh.vertices[i]);
    face.offset /= static_cast<double>(face.loop.size());
    for (std::size_t k = 0; k < face.loop.size(); ++k) {
      const int a = face.loop[k], b = face.loop[(k + 1) % face.loop.size()];
      edges.insert({std::min(a, b), std::max(a, b)});
    }
  }
  mesh.edges.clear();
  mesh.edgeDirections.clear();
  for (const auto& [a, b] : edges) {
    mesh.edges.push_back({a, b});
    addEdgeDirection(mesh.edgeDirections, (mesh.vertices[b] - mesh.vertices[a]).normalized());
  }
}

ConvexMesh boxPolyhedron(const Vec3& h) {
  ConvexMesh box;
  for (int k = 0; k < 8; ++k)
    box.vertices.emplace_back((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(),
                              (k & 4) ? h.z() : -h.z());
  // Loops counter-clockwise seen from outside: -z, +z, -y, +y, -x, +x.
  static constexpr int kLoops[6][4] = {{0, 2, 3, 1}, {4, 5, 7, 6}, {0, 1, 5, 4},
                                       {2, 6, 7, 3}, {0, 4, 6, 2}, {1, 3, 7, 5}};
  static constexpr int kAxis[6] = {2, 2, 1, 1, 0, 0};
  for (int f = 0; f < 6; ++f) {
    Vec3 n = Vec3::Zero();
    n[kAxis[f]] = (f % 2 == 0) ? -1.0 : 1.0;
    box.faces.push_back({n, h[kAxis[f]], {kLoops[f], kLoops[f] + 4}});
  }
  for (int k = 0; k < 8; ++k)
    for (int bit = 1; bit < 8; bit <<= 1)
      if (!(k & bit)) box.edges.push_back({k, k | bit});
  box.edgeDirections = {Vec3::UnitX(), Vec3::UnitY(), Vec3::UnitZ()};
  return box;
}

}  // namespace msim::rigid
