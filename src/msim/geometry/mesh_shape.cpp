#include "msim/geometry/mesh_shape.hpp"

#include <cmath>
#include <limits>
#include <numbers>

#include "msim/geometry/mesh_distance_field.hpp"
#include "msim/geometry/triangle_queries.hpp"

namespace msim::geometry {

MeshShape::MeshShape(TriangleMesh mesh) : mesh_(std::move(mesh)) {
  constexpr double inf = std::numeric_limits<double>::infinity();
  bounds_ = {Vec3::Constant(inf), Vec3::Constant(-inf)};
  for (const Vec3& v : mesh_.vertices) {
    bounds_.min = bounds_.min.cwiseMin(v);
    bounds_.max = bounds_.max.cwiseMax(v);
  }
}

double MeshShape::distance(const Vec3& x) const {
  double nearestSq = std::numeric_limits<double>::infinity();
  double totalSolidAngle = 0.0;
  for (const auto& t : mesh_.triangles) {
    const Vec3& a = mesh_.vertices[t[0]];
    const Vec3& b = mesh_.vertices[t[1]];
    const Vec3& c = mesh_.vertices[t[2]];
    nearestSq = std::min(nearestSq, (closestPointOnTriangle(x, a, b, c) - x).squaredNorm());
    totalSolidAngle += solidAngle(x, a, b, c);
  }
  // Winding number is +-1 inside a closed mesh (sign depends on its orientation), 0 outside.
  const bool inside = std::abs(totalSolidAngle) > 2.0 * std::numbers::pi;
  const double unsignedDistance = std::sqrt(nearestSq);
  return inside ? -unsignedDistance : unsignedDistance;
}

Grid<float, 3> MeshShape::distanceField(const GridSpec<3>& spec) const { return meshDistanceField(mesh_, spec); }

}  // namespace msim::geometry
