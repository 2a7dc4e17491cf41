#include "msim/geometry/occupancy.hpp"

#include <gtest/gtest.h>

#include <numbers>

#include "msim/geometry/analytic_shapes.hpp"

namespace msim::geometry {
namespace {

template <int D>
double solidVolume(const Grid<float, D>& fraction) {
  double sum = 0.0;
  for (float f : fraction.data()) sum += f;
  return sum * fraction.spec().cellVolume();
}

TEST(Occupancy, SphereVolumeWithinTwoPercent) {
  const double r = 0.3;
  const Sphere<3> sphere(Vec3(0.5, 0.5, 0.5), r);
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 32, IVec3::Constant(32));  // ~19 cells across
  const double exact = 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(solidVolume(occupancy(sphere, spec)), exact, 0.02 * exact);
}

TEST(Occupancy, IsOneInsideZeroOutsideAndRampsAtTheSurface) {
  const Box<2> box(Vec2(0.0, 0.0), Vec2(0.45, 1.0));
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(10, 10));
  const auto f = occupancy(box, spec);
  EXPECT_FLOAT_EQ(f(IVec2(1, 5)), 1.0f);
  EXPECT_FLOAT_EQ(f(IVec2(7, 5)), 0.0f);
  EXPECT_NEAR(f(IVec2(4, 5)), 0.5f, 1e-5f);  // face x = 0.45 crosses the middle of cell 4
  // An axis-aligned face is captured exactly: area 0.45 * 1.0.
  EXPECT_NEAR(solidVolume(f), 0.45, 1e-5);
}

}  // namespace
}  // namespace msim::geometry
