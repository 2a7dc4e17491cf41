#include "msim/io/level_set_mesh.hpp"

#include <algorithm>
#include <cmath>
#include <vector>

#include <openvdb/openvdb.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <openvdb/tools/VolumeToMesh.h>

namespace msim::io {

TriangleMesh levelSetMesh(const Grid<float, 3>& phi, int halfWidth) {
  openvdb::initialize();
  const GridSpec<3>& spec = phi.spec();
  const float background = static_cast<float>(halfWidth * spec.dx);
  auto grid = openvdb::FloatGrid::create(background);
  grid->setGridClass(openvdb::GRID_LEVEL_SET);
  // Index (i, j, k) is the cell centre origin + (i + 1/2) dx: the transform places voxel centres
  // there, so the mesh comes out in world coordinates.
  auto transform = openvdb::math::Transform::createLinearTransform(spec.dx);
  transform->postTranslate(openvdb::Vec3d(spec.origin.x() + 0.5 * spec.dx, spec.origin.y() + 0.5 * spec.dx,
                                          spec.origin.z() + 0.5 * spec.dx));
  grid->setTransform(transform);
  auto accessor = grid->getAccessor();
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const float v = phi[i];
    if (std::abs(v) >= background) continue;
    const IVec3 c = phi.coord(i);
    accessor.setValue(openvdb::Coord(c.x(), c.y(), c.z()), v);
  }
  // The inactive voxels take the background's magnitude with the sign of the side they are on;
  // left all positive, the liquid's interior beyond the band would read as air and add an inner
  // surface.
  openvdb::tools::signedFloodFill(grid->tree());
  std::vector<openvdb::Vec3s> points;
  std::vector<openvdb::Vec3I> triangles;
  std::vector<openvdb::Vec4I> quads;
  openvdb::tools::volumeToMesh(*grid, points, triangles, quads, 0.0, 0.0);
  TriangleMesh mesh;
  mesh.vertices.reserve(points.size());
  for (const auto& p : points) mesh.vertices.emplace_back(p.x(), p.y(), p.z());
  mesh.triangles.reserve(triangles.size() + 2 * quads.size());
  // OpenVDB orients its polygons with the normals pointing into the level set's negative side;
  // reversing them makes them point out of the liquid, as renderers expect.
  for (const auto& t : triangles) mesh.triangles.push_back({int(t[2]), int(t[1]), int(t[0])});
  for (const auto& q : quads) {
    mesh.triangles.push_back({int(q[2]), int(q[1]), int(q[0])});
    mesh.triangles.push_back({int(q[3]), int(q[2]), int(q[0])});
  }
  return mesh;
}

}  // namespace msim::io
