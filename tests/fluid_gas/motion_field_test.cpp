// The motion-field primitives against the properties Stam states for them (ch. 6.3.1, App. 6.A).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "msim/fluid/gas/motion_field.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {
MotionFieldInstance make(MotionPrimitive type) {
  MotionFieldInstance m;
  m.type = type;
  return m;
}
}  // namespace

TEST(MotionField, LineVortexHasUnitCirculationAndNoDivergence) {
  MotionFieldInstance v = make(MotionPrimitive::LineVortex);
  v.coreRadius = 0.01;
  const MotionField field({v});
  for (double r : {0.2, 0.5, 1.5}) {
    const int n = 4000;
    double circulation = 0.0;
    for (int i = 0; i < n; ++i) {
      const double t = 2 * std::numbers::pi * (i + 0.5) / n;
      const Vec3 p(r * std::cos(t), r * std::sin(t), 0.3);
      const Vec3 tangent(-std::sin(t), std::cos(t), 0.0);
      circulation += field.velocity(p).dot(tangent) * r * 2 * std::numbers::pi / n;
    }
    EXPECT_NEAR(circulation, 1.0, 1e-6) << "r = " << r;
  }
  const Vec3 p(0.3, -0.4, 0.1);
  const double h = 1e-5;
  double div = 0.0;
  for (int a = 0; a < 3; ++a) {
    Vec3 e = Vec3::Zero();
    e[a] = h;
    div += (field.velocity(p + e)[a] - field.velocity(p - e)[a]) / (2 * h);
  }
  EXPECT_NEAR(div, 0.0, 1e-6);
}

TEST(MotionField, RingVortexIsAxialOnItsAxisAndCirculatesAroundTheFilament) {
  MotionFieldInstance ring = make(MotionPrimitive::RingVortex);
  ring.ringRadius = 1.0;
  ring.coreRadius = 0.0;
  for (double z : {-0.2, 0.0, 0.3}) {
    const Vec3 u = MotionField::primitive(ring, Vec3(0.0, 0.0, z));
    EXPECT_NEAR(u.x(), 0.0, 1e-12);
    EXPECT_NEAR(u.y(), 0.0, 1e-12);
    EXPECT_GT(u.z(), 0.0);
  }
  // Velocity is perpendicular to the offset from the closest filament point (it circulates).
  const Vec3 p(1.2, 0.0, 0.15);
  const Vec3 offset = p - Vec3(1.0, 0.0, 0.0);
  EXPECT_NEAR(MotionField::primitive(ring, p).dot(offset), 0.0, 1e-12);
}

TEST(MotionField, RadialConeAndDirectionalSupports) {
  const MotionFieldInstance radial = make(MotionPrimitive::Radial);
  EXPECT_GT(MotionField::primitive(radial, Vec3(2, 0, 0)).x(), 0.0);   // outwards outside
  EXPECT_LT(MotionField::primitive(radial, Vec3(0.5, 0, 0)).x(), 0.0); // inwards inside
  const MotionFieldInstance cone = make(MotionPrimitive::Cone);
  EXPECT_EQ(MotionField::primitive(cone, Vec3(1, 0, 0.5)), Vec3::Zero());   // outside the cone
  EXPECT_EQ(MotionField::primitive(cone, Vec3(0.1, 0, -1)), Vec3::Zero());  // lower nappe excluded
  EXPECT_NEAR(MotionField::primitive(cone, Vec3(0.3, 0, 0.4)).norm(), 1.0, 1e-12);
  MotionFieldInstance dir = make(MotionPrimitive::Directional);
  dir.halfDistance = 2.0;
  EXPECT_EQ(MotionField::primitive(dir, Vec3(1.5, 0, 1)), Vec3::Zero());
  EXPECT_EQ(MotionField::primitive(dir, Vec3(0, 0, -1)), Vec3::Zero());
  EXPECT_NEAR(MotionField::primitive(dir, Vec3(0.5, -0.5, 2.0)).z(), 0.5, 1e-12);  // halves at d_half
  dir.edgeSoftness = 0.5;  // fades continuously to zero at the edge, unchanged in the core
  EXPECT_NEAR(MotionField::primitive(dir, Vec3(0.4, -0.2, 2.0)).z(), 0.5, 1e-12);
  EXPECT_NEAR(MotionField::primitive(dir, Vec3(0.999, 0.0, 2.0)).z(), 0.0, 1e-4);
  EXPECT_NEAR(MotionField::primitive(dir, Vec3(0.75, 0.0, 2.0)).z(), 0.25, 1e-12);  // smoothstep(1/2) = 1/2
}

TEST(MotionField, InstanceTransformRotatesTheField) {
  MotionFieldInstance base = make(MotionPrimitive::Cone);
  base.halfDistance = 1.5;
  MotionFieldInstance rotated = base;
  const Eigen::Matrix3d R = Eigen::AngleAxisd(0.7, Vec3(1, 2, -1).normalized()).toRotationMatrix();
  rotated.axis = R * Vec3::UnitZ();
  rotated.position = Vec3(0.5, -1.0, 2.0);
  const MotionField a({base}), b({rotated});
  for (const Vec3& x : {Vec3(0.1, 0.2, 0.9), Vec3(-0.3, 0.1, 0.5), Vec3(0.2, 0.2, 2.0)}) {
    // Equal up to the roll about the axis, which the axisymmetric cone does not see.
    const Vec3 expected = R * a.velocity(x);
    const Vec3 got = b.velocity(rotated.position + R * x);
    EXPECT_NEAR((expected - got).norm(), 0.0, 1e-9);
  }
}

TEST(MotionField, FieldsSum) {
  MotionFieldInstance wind = make(MotionPrimitive::Uniform);
  wind.axis = Vec3::UnitX();
  wind.magnitude = 2.0;
  MotionFieldInstance up = make(MotionPrimitive::Uniform);
  up.magnitude = 0.5;
  const MotionField field({wind, up});
  EXPECT_NEAR((field.velocity(Vec3(3, 4, 5)) - Vec3(2.0, 0.0, 0.5)).norm(), 0.0, 1e-12);
}
