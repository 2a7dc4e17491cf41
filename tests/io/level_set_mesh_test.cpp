// The surface mesh of a level set (OpenVDB's volumeToMesh): a sphere's mesh lies on the sphere,
// encloses its volume with outward-facing triangles, and a phi without a crossing gives no mesh.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "msim/io/level_set_mesh.hpp"

using namespace msim;

TEST(LevelSetMesh, SphereMeshLiesOnTheSphereAndFacesOutwards) {
  const GridSpec<3> spec(Vec3(-0.1, 0.0, 0.2), 1.0 / 48.0, IVec3::Constant(48));
  const Vec3 centre(0.4, 0.5, 0.7);
  const double radius = 0.3;
  Grid<float, 3> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>((phi.position(phi.coord(i)) - centre).norm() - radius);
  const TriangleMesh mesh = io::levelSetMesh(phi);
  ASSERT_GT(mesh.triangles.size(), 1000u);
  double worst = 0.0;
  for (const Vec3& v : mesh.vertices) worst = std::max(worst, std::abs((v - centre).norm() - radius));
  EXPECT_LT(worst, 0.1 * spec.dx);
  // Signed volume by the divergence theorem: positive when the triangles face outwards.
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
  const double exact = 4.0 / 3.0 * std::numbers::pi * radius * radius * radius;
  EXPECT_NEAR(volume / exact, 1.0, 0.01);
}

TEST(LevelSetMesh, NoCrossingNoMesh) {
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3::Constant(8));
  const TriangleMesh mesh = io::levelSetMesh(Grid<float, 3>(spec, 0.3f));
  EXPECT_TRUE(mesh.triangles.empty());
}
