#include "msim/geometry/mesh_shape.hpp"

#include <gtest/gtest.h>

#include <random>

#include "cube_mesh.hpp"
#include "msim/geometry/analytic_shapes.hpp"
#include "msim/geometry/mesh_distance_field.hpp"

namespace msim::geometry {
namespace {

using testing::unitCubeMesh;

TEST(MeshShape, PointDistanceMatchesBoxExactly) {
  const MeshShape mesh(unitCubeMesh());
  const Box<3> box(Vec3::Zero(), Vec3::Ones());
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(-0.6, 1.6);
  for (int n = 0; n < 500; ++n) {
    const Vec3 x(u(rng), u(rng), u(rng));
    EXPECT_NEAR(mesh.distance(x), box.distance(x), 1e-9) << x.transpose();
  }
  EXPECT_EQ(mesh.bounds().min, Vec3::Zero());
  EXPECT_EQ(mesh.bounds().max, Vec3::Ones());
}

TEST(MeshShape, SignDoesNotDependOnWinding) {
  TriangleMesh inverted = unitCubeMesh();
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  const MeshShape mesh(std::move(inverted));
  EXPECT_NEAR(mesh.distance(Vec3(0.5, 0.5, 0.4)), -0.4, 1e-12);
  EXPECT_NEAR(mesh.distance(Vec3(2, 0.5, 0.5)), 1.0, 1e-12);
}

TEST(MeshDistanceField, MatchesBoxNearSurfaceAndSignEverywhere) {
  // Grid of 0.05 m cells over [-0.5, 1.5]^3, offset so cell centres do not sit on the faces.
  const double dx = 0.05;
  const GridSpec<3> spec(Vec3::Constant(-0.53), dx, IVec3::Constant(42));
  const float halfBand = 3.0f;
  const auto field = meshDistanceField(unitCubeMesh(), spec, halfBand);
  const Box<3> box(Vec3::Zero(), Vec3::Ones());
  int nearSurface = 0;
  for (std::size_t i = 0; i < field.count(); ++i) {
    const Vec3 x = field.position(field.coord(i));
    const double exact = box.distance(x);
    if (std::abs(exact) < 2.0 * dx) {
      ++nearSurface;
      EXPECT_NEAR(field[i], exact, 0.5 * dx) << x.transpose();
    }
    if (std::abs(exact) > 1e-6) {
      EXPECT_EQ(field[i] < 0.0f, exact < 0.0) << x.transpose();
    }
    EXPECT_LE(std::abs(field[i]), halfBand * dx * 1.0001);
  }
  EXPECT_GT(nearSurface, 1000);
  // Deep inside, beyond the band: clamped magnitude, but negative.
  EXPECT_FLOAT_EQ(field(IVec3(21, 21, 21)), static_cast<float>(-halfBand * dx));
}

TEST(MeshShape, DistanceFieldUsesTheNarrowBand) {
  const MeshShape mesh(unitCubeMesh());
  const GridSpec<3> spec(Vec3::Constant(-0.2), 0.1, IVec3::Constant(15));
  const auto field = mesh.distanceField(spec);
  EXPECT_NEAR(field(IVec3(2, 7, 7)), -0.05, 1e-4);  // centre x = 0.05, nearest face x = 0
  EXPECT_NEAR(field(IVec3(1, 7, 7)), 0.05, 1e-4);
}

}  // namespace
}  // namespace msim::geometry
