#pragma once
// A closed triangle mesh as a Shape.
#include "msim/geometry/shape.hpp"
#include "msim/core/triangle_mesh.hpp"

namespace msim::geometry {

class MeshShape final : public Shape<3> {
 public:
  // The mesh should be closed (watertight); its winding may be either way.
  explicit MeshShape(TriangleMesh mesh);

  // Exact: nearest point over all triangles, sign from the winding number. O(triangles) per
  // call, meant for point probes; use distanceField for whole grids.
  double distance(const Vec3& x) const override;
  Bounds<3> bounds() const override { return bounds_; }
  // OpenVDB narrow band: exact near the surface, magnitude clamped farther away
  // (see meshDistanceField).
  Grid<float, 3> distanceField(const GridSpec<3>& spec) const override;

  const TriangleMesh& mesh() const { return mesh_; }

 private:
  TriangleMesh mesh_;
  Bounds<3> bounds_;
};

}  // namespace msim::geometry
