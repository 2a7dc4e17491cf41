// Compound bodies: mass properties against an independent divergence-theorem mesh of the same
// solid, the parallel-axis term, contacts part by part, and a hinged paddle wheel.
#include "msim/rigid/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <string>

#include "msim/core/error.hpp"
#include "msim/rigid/mass_properties.hpp"
#include "rotations.hpp"

namespace msim::rigid {
namespace {

using testing::about;

// The L-shaped prism {(x, z) in the L below} x [0, 1] in y as a closed outward-wound mesh.
// L in the (x, z) plane, counter-clockwise: (0,0) (2,0) (2,0.5) (0.5,0.5) (0.5,2) (0,2).
TriangleMesh lPrismMesh() {
  const double xz[6][2] = {{0, 0}, {2, 0}, {2, 0.5}, {0.5, 0.5}, {0.5, 2}, {0, 2}};
  TriangleMesh m;
  for (double y : {0.0, 1.0})
    for (const auto& p : xz) m.vertices.emplace_back(p[0], y, p[1]);
  // Counter-clockwise in (x, z) faces -y (x cross z = -y): the y = 0 cap keeps that order, the
  // y = 1 cap reverses it. Fans from the reflex corner 3 cover the L.
  for (int k : {4, 5, 0, 1}) {
    const int next = k == 5 ? 0 : k + 1;
    m.triangles.push_back({3, k, next});
    m.triangles.push_back({9, next + 6, k + 6});
  }
  for (int i = 0; i < 6; ++i) {
    const int j = (i + 1) % 6;
    m.triangles.push_back({i, i + 6, j + 6});
    m.triangles.push_back({i, j + 6, j});
  }
  return m;
}

// The same L as two boxes; the upright one is given lying along x and turned 90 deg about y.
std::vector<CompoundPart> lParts() {
  return {{Box{Vec3(1.0, 0.5, 0.25)}, Vec3(1.0, 0.5, 0.25), Eigen::Quaterniond::Identity()},
          {Box{Vec3(0.75, 0.5, 0.25)}, Vec3(0.25, 0.5, 1.25), about(std::numbers::pi / 2, Vec3::UnitY())}};
}

TEST(RigidCompound, ParallelAxisInertiaOfPointMass) {
  const Eigen::Matrix3d onZ = parallelAxisInertia(2.0, Vec3(0, 0, 3));
  EXPECT_LE((onZ - Eigen::Vector3d(18, 18, 0).asDiagonal().toDenseMatrix()).norm(), 1e-14);
  // Off-diagonal products of inertia: -m d_i d_j.
  const Eigen::Matrix3d general = parallelAxisInertia(0.5, Vec3(1, 2, 3));
  Eigen::Matrix3d expected;
  expected << 6.5, -1, -1.5, -1, 5, -3, -1.5, -3, 2.5;
  EXPECT_LE((general - expected).norm(), 1e-14);
}

TEST(RigidCompound, LShapeMassPropertiesMatchMeshOfTheSameSolid) {
  const double rho = 700.0;
  const MassProperties mesh = meshMassProperties(lPrismMesh(), rho);
  const MassProperties parts = shapeMassProperties(Compound{lParts()}, rho);
  EXPECT_NEAR(parts.mass, rho * 1.75, 1e-9);  // area 2 * 0.5 + 0.5 * 1.5, depth 1
  EXPECT_NEAR(parts.mass, mesh.mass, 1e-9);
  EXPECT_LE((parts.centreOfMass - mesh.centreOfMass).norm(), 1e-12);
  EXPECT_LE((parts.inertia - mesh.inertia).cwiseAbs().maxCoeff(), 1e-9 * mesh.inertia.norm());
  // makeCompound moves the centre of mass to the origin and keeps the inertia about it.
  const Compound c = makeCompound(lParts());
  const MassProperties centred = shapeMassProperties(c, rho);
  EXPECT_LE(centred.centreOfMass.norm(), 1e-12);
  EXPECT_LE((centred.inertia - mesh.inertia).cwiseAbs().maxCoeff(), 1e-9 * mesh.inertia.norm());
  EXPECT_LE((c.parts[0].offset - (Vec3(1.0, 0.5, 0.25) - mesh.centreOfMass)).norm(), 1e-12);
  std::printf("L compound: centre (%.6f, %.6f, %.6f), I_xx %.4f I_xz %.4f (mesh %.4f %.4f)\n",
              parts.centreOfMass.x(), parts.centreOfMass.y(), parts.centreOfMass.z(),
              parts.inertia(0, 0), parts.inertia(0, 2), mesh.inertia(0, 0), mesh.inertia(0, 2));
}

TEST(RigidCompound, LShapeSettlesOnFloorPartByPart) {
  World w;
  w.addPlane(Plane{Vec3::UnitZ(), 0.0, Material{0.5, 0.0}});
  RigidBody l = RigidBody::fromDensity(makeCompound(lParts()), 700.0);
  l.position = Vec3(0, 0, 1.5);
  l.orientation = about(0.3, Vec3(1, 1, 0));
  const int i = w.addBody(l);
  for (int k = 0; k < 3000; ++k) w.step(1e-3);
  // Lowest point over all parts' corners touches the floor; the body is at rest.
  const RigidBody& b = w.body(i);
  double lowest = 1e9;
  for (const CompoundPart& part : std::get<Compound>(b.shape()).parts)
    for (int k = 0; k < 8; ++k) {
      const Vec3& h = std::get<Box>(part.shape).halfExtents;
      const Vec3 corner((k & 1) ? h.x() : -h.x(), (k & 2) ? h.y() : -h.y(), (k & 4) ? h.z() : -h.z());
      lowest = std::min(lowest, b.toWorld(part.offset + part.rotation * corner).z());
    }
  EXPECT_NEAR(lowest, 0.0, 1e-3);
  EXPECT_LE(b.velocity.norm(), 1e-2);
}

TEST(RigidCompound, HingedPaddleWheelSpinsUpAtTorqueOverInertia) {
  // Hub sphere plus 4 blades at 90 deg about the axle (y). Each blade, side lengths 0.4 (radial)
  // x 0.1 (along y) x 0.04, centred 0.3 from the axle: I_y = m/12 (0.4^2 + 0.04^2) + m 0.3^2.
  const double rho = 500.0, r = 0.1, torque = 2.0, dt = 1e-3;
  std::vector<CompoundPart> parts{{Sphere{r}, Vec3::Zero(), Eigen::Quaterniond::Identity()}};
  for (int k = 0; k < 4; ++k) {
    const Eigen::Quaterniond q = about(k * std::numbers::pi / 2, Vec3::UnitY());
    parts.push_back({Box{Vec3(0.2, 0.05, 0.02)}, q * Vec3(0.3, 0, 0), q});
  }
  const double hubMass = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  const double bladeMass = rho * 0.4 * 0.1 * 0.04;
  const double Iy = 0.4 * hubMass * r * r +
                    4 * (bladeMass / 12 * (0.4 * 0.4 + 0.04 * 0.04) + bladeMass * 0.3 * 0.3);
  World w;  // with gravity: the centre of mass is on the axle, so it exerts no torque
  RigidBody wheel = RigidBody::fromDensity(makeCompound(parts), rho);
  EXPECT_NEAR(wheel.bodyInertia()(1, 1), Iy, 1e-12 * Iy);
  wheel.position = Vec3(0, 0, 1);
  const int i = w.addBody(wheel);
  w.addHinge(i, Vec3(0, 0, 1), Vec3::UnitY());
  const int steps = 500;
  for (int k = 0; k < steps; ++k) {
    w.body(i).torque = Vec3(0, torque, 0);
    w.step(dt);
  }
  const double expected = torque * steps * dt / Iy;
  const RigidBody& b = w.body(i);
  std::printf("paddle wheel: omega_y %.6f rad/s after %.1f s, torque / I_y * t = %.6f; pivot drift "
              "%.3g m\n", b.angularVelocity.y(), steps * dt, expected, (b.position - Vec3(0, 0, 1)).norm());
  EXPECT_NEAR(b.angularVelocity.y(), expected, 1e-3 * expected);
  EXPECT_LE((b.position - Vec3(0, 0, 1)).norm(), 1e-4);
}

TEST(RigidCompound, PaddleWheelBladeStopsOnAStaticBox) {
  // Gravity swings a one-bladed wheel (hub on the axle, blade level along +x) down onto a static
  // block under the blade tip; the blade part, not the hub, must come to rest on the block.
  std::vector<CompoundPart> parts{{Sphere{0.05}, Vec3::Zero(), Eigen::Quaterniond::Identity()},
                                  {Box{Vec3(0.2, 0.05, 0.02)}, Vec3(0.25, 0, 0), Eigen::Quaterniond::Identity()}};
  World w;
  RigidBody wheel = RigidBody::fromDensity(makeCompound(parts), 500.0);
  const Vec3 axle(0, 0, 1);
  const Compound& c = std::get<Compound>(wheel.shape());
  wheel.position = axle - c.parts[0].offset;  // the hub centre on the axle
  const int i = w.addBody(wheel);
  w.addHinge(i, axle, Vec3::UnitY());
  RigidBody block = RigidBody::makeStatic(Box{Vec3(0.1, 0.2, 0.5)});
  block.position = Vec3(0.35, 0, 1 - 0.02 - 0.5 - 0.05);  // top 5 cm below the level blade
  w.addBody(block);
  for (int k = 0; k < 2000; ++k) w.step(1e-3);
  const RigidBody& b = w.body(i);
  const Vec3 bladeCentre = b.toWorld(c.parts[1].offset);
  const double tilt = std::atan2(axle.z() - bladeCentre.z(), bladeCentre.x() - axle.x());
  // The blade's lower tip corner (0.45 out, 0.02 below the centre line) rests on the block top,
  // 0.07 below the axle: 0.45 sin(t) + 0.02 cos(t) = 0.07.
  const double expected = std::asin(0.07 / std::hypot(0.45, 0.02)) - std::atan2(0.02, 0.45);
  std::printf("paddle blade on block: tilt %.5f rad (expected %.5f), omega %.3g rad/s\n", tilt,
              expected, b.angularVelocity.norm());
  EXPECT_NEAR(tilt, expected, 1e-3);
  EXPECT_LE(b.angularVelocity.norm(), 1e-2);
}

TEST(RigidCompound, RejectsBadParts) {
  EXPECT_THROW(makeCompound({}), InputError);
  try {
    makeCompound({{Sphere{0.1}, Vec3::Zero(), Eigen::Quaterniond::Identity()},
                  {Box{Vec3(0.1, 0.0, 0.1)}, Vec3::Zero(), Eigen::Quaterniond::Identity()}});
    ADD_FAILURE() << "zero half extent accepted";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("part 1"), std::string::npos) << e.what();
  }
  EXPECT_THROW(makeCompound({{Sphere{0.1}, Vec3::Zero(), Eigen::Quaterniond(0, 0, 0, 0)}}),
               InputError);
  EXPECT_THROW(RigidBody::fromDensity(Compound{}, 1.0), InputError);
}

}  // namespace
}  // namespace msim::rigid
