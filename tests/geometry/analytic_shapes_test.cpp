#include "msim/geometry/analytic_shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>

namespace msim::geometry {
namespace {

TEST(Sphere, DistanceIsRadialMinusRadius) {
  const Sphere<3> s(Vec3(1, 2, 3), 0.5);
  EXPECT_DOUBLE_EQ(s.distance(Vec3(1, 2, 3)), -0.5);
  EXPECT_DOUBLE_EQ(s.distance(Vec3(1, 2, 5)), 1.5);
  EXPECT_NEAR(s.distance(Vec3(1.3, 2.4, 3)), 0.0, 1e-12);
  EXPECT_EQ(s.bounds().min, Vec3(0.5, 1.5, 2.5));
  EXPECT_EQ(s.bounds().max, Vec3(1.5, 2.5, 3.5));
}

TEST(Sphere, WorksAsCircleIn2D) {
  const Sphere<2> c(Vec2(0, 0), 1.0);
  EXPECT_DOUBLE_EQ(c.distance(Vec2(3, 4)), 4.0);
  EXPECT_DOUBLE_EQ(c.distance(Vec2(0.5, 0)), -0.5);
}

TEST(Box, FaceEdgeAndCornerDistancesOutside) {
  const Box<3> b(Vec3(0, 0, 0), Vec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(b.distance(Vec3(1.5, 1, 1)), 0.5);                     // face
  EXPECT_DOUBLE_EQ(b.distance(Vec3(-3, -4, 1)), 5.0);                     // edge: hypot(3, 4)
  EXPECT_DOUBLE_EQ(b.distance(Vec3(2, 4, 5)), std::sqrt(1.0 + 4 + 4));    // corner: Euclidean
  EXPECT_DOUBLE_EQ(b.distance(Vec3(-1, -1, -1)), std::sqrt(3.0));         // lower corner
}

TEST(Box, InsideIsMinusDistanceToNearestFace) {
  const Box<3> b(Vec3(0, 0, 0), Vec3(1, 2, 3));
  EXPECT_DOUBLE_EQ(b.distance(Vec3(0.5, 1, 1.5)), -0.5);
  EXPECT_NEAR(b.distance(Vec3(0.9, 1, 1.5)), -0.1, 1e-12);
  EXPECT_NEAR(b.distance(Vec3(0.5, 1.95, 1.5)), -0.05, 1e-12);
  EXPECT_DOUBLE_EQ(b.distance(Vec3(1, 1, 1)), 0.0);
}

TEST(Box, WorksAsRectangleIn2D) {
  const Box<2> r(Vec2(0, 0), Vec2(2, 1));
  EXPECT_DOUBLE_EQ(r.distance(Vec2(5, 5)), 5.0);  // corner (2,1) -> (5,5): hypot(3, 4)
  EXPECT_DOUBLE_EQ(r.distance(Vec2(1, 0.25)), -0.25);
}

TEST(Capsule, DistanceToSegmentMinusRadius) {
  const Capsule<3> c(Vec3(0, 0, 0), Vec3(0, 2, 0), 0.5);
  EXPECT_DOUBLE_EQ(c.distance(Vec3(1, 1, 0)), 0.5);        // beside the segment
  EXPECT_DOUBLE_EQ(c.distance(Vec3(0, 4, 0)), 1.5);        // beyond end b
  EXPECT_DOUBLE_EQ(c.distance(Vec3(0, -3, 4)), 4.5);       // beyond end a: |(0,-3,4)| - 0.5
  EXPECT_DOUBLE_EQ(c.distance(Vec3(0, 1, 0)), -0.5);       // on the axis
  EXPECT_EQ(c.bounds().min, Vec3(-0.5, -0.5, -0.5));
  EXPECT_EQ(c.bounds().max, Vec3(0.5, 2.5, 0.5));
}

TEST(Capsule, DegenerateSegmentIsSphere) {
  const Capsule<2> c(Vec2(1, 1), Vec2(1, 1), 1.0);
  EXPECT_DOUBLE_EQ(c.distance(Vec2(4, 5)), 4.0);
}

TEST(Plane, SolidIsBehindTheNormal) {
  const Plane<3> p(Vec3(0, 1, 0), Vec3(0, 2, 0));  // unnormalised normal
  EXPECT_DOUBLE_EQ(p.distance(Vec3(5, 3, -7)), 2.0);
  EXPECT_DOUBLE_EQ(p.distance(Vec3(0, 0.25, 0)), -0.75);
  const Plane<2> tilted(Vec2(0, 0), Vec2(1, 1));
  EXPECT_NEAR(tilted.distance(Vec2(1, 1)), std::sqrt(2.0), 1e-12);
  EXPECT_TRUE(std::isinf(p.bounds().max.x()));
}

TEST(Shape, DistanceFieldSamplesCellCentres) {
  const Sphere<2> c(Vec2(0, 0), 1.0);
  const GridSpec<2> spec(Vec2(0, 0), 0.5, IVec2(4, 2));
  const auto field = c.distanceField(spec);
  EXPECT_FLOAT_EQ(field(IVec2(0, 0)), static_cast<float>(std::sqrt(0.125) - 1.0));
  EXPECT_FLOAT_EQ(field(IVec2(3, 1)), static_cast<float>(std::hypot(1.75, 0.75) - 1.0));
}

TEST(Cylinder, SideCapAndRimDistances) {
  // Axis along y from (0,0,0) to (0,2,0), radius 1: side, cap and rim (edge) regions, inside.
  const Cylinder<3> c(Vec<3>(0, 0, 0), Vec<3>(0, 2, 0), 1.0);
  EXPECT_NEAR(c.distance(Vec<3>(3, 1, 0)), 2.0, 1e-12);                  // beside the side
  EXPECT_NEAR(c.distance(Vec<3>(0.5, 3.5, 0)), 1.5, 1e-12);              // above the cap
  EXPECT_NEAR(c.distance(Vec<3>(4, -4, 0)), std::hypot(3.0, 4.0), 1e-12);  // past the rim
  EXPECT_NEAR(c.distance(Vec<3>(0, 1, 0.5)), -0.5, 1e-12);               // nearer the side than the caps
  EXPECT_NEAR(c.distance(Vec<3>(0, 0.2, 0)), -0.2, 1e-12);               // nearer the bottom cap
  const auto b = c.bounds();
  EXPECT_NEAR(b.min.x(), -1.0, 1e-12);
  EXPECT_NEAR(b.max.y(), 2.0, 1e-12);
}

}  // namespace
}  // namespace msim::geometry
