#include "msim/geometry/mesh_distance_field.hpp"

#include <openvdb/openvdb.h>
#include <openvdb/tools/MeshToVolume.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

namespace msim::geometry {

Grid<float, 3> meshDistanceField(const TriangleMesh& mesh, const GridSpec<3>& spec, float halfBandCells) {
  openvdb::initialize();
  // Voxel (i,j,k) of the VDB grid sits exactly on cell centre (i,j,k) of `spec`, so sampling
  // needs no interpolation.
  auto transform = openvdb::math::Transform::createLinearTransform(spec.dx);
  const Vec3 firstCenter = spec.cellCenter(IVec3::Zero());
  transform->postTranslate(openvdb::Vec3d(firstCenter.x(), firstCenter.y(), firstCenter.z()));

  std::vector<openvdb::Vec3s> points;
  points.reserve(mesh.vertices.size());
  for (const Vec3& v : mesh.vertices) points.emplace_back(float(v.x()), float(v.y()), float(v.z()));
  std::vector<openvdb::Vec3I> triangles;
  triangles.reserve(mesh.triangles.size());
  for (const auto& t : mesh.triangles) triangles.emplace_back(t[0], t[1], t[2]);

  const auto levelSet = openvdb::tools::meshToLevelSet<openvdb::FloatGrid>(*transform, points, triangles, halfBandCells);

  Grid<float, 3> field(spec);
  tbb::parallel_for(tbb::blocked_range<int>(0, spec.res.z()), [&](const tbb::blocked_range<int>& slices) {
    // Accessors cache tree nodes and are not thread-safe: one per task.
    auto accessor = levelSet->getConstAccessor();
    for (int k = slices.begin(); k != slices.end(); ++k)
      for (int j = 0; j < spec.res.y(); ++j)
        for (int i = 0; i < spec.res.x(); ++i) field(IVec3(i, j, k)) = accessor.getValue(openvdb::Coord(i, j, k));
  });
  return field;
}

}  // namespace msim::geometry
