// Contacts and the sequential-impulse solver against analytic expectations.
#include "msim/rigid/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>

#include "msim/rigid/mass_properties.hpp"
#include "test_meshes.hpp"

namespace msim::rigid {
namespace {

constexpr double kG = 9.81;

World floorWorld() {
  World w;
  w.addPlane(Plane{Vec3::UnitZ(), 0.0, Material{0.5, 0.0}});
  return w;
}

TEST(RigidContact, BallRestingOnFloorNeitherDriftsNorSinks) {
  World w = floorWorld();
  RigidBody ball = RigidBody::fromDensity(Sphere{0.5}, 1000.0);
  ball.position = Vec3(0.2, -0.3, 0.5);
  const int i = w.addBody(ball);
  for (int k = 0; k < 1000; ++k) w.step(1e-3);
  EXPECT_LE((w.body(i).position - Vec3(0.2, -0.3, 0.5)).norm(), 1e-4);
  std::printf("resting ball: drift %.3g m\n", (w.body(i).position - Vec3(0.2, -0.3, 0.5)).norm());
  EXPECT_LE(w.body(i).velocity.norm(), 1e-3);
}

TEST(RigidContact, BounceReachesRestitutionSquaredHeight) {
  // A drop from h0 hits at sqrt(2 g h0), leaves at e times that and rises to e^2 h0.
  for (double e : {0.5, 0.8}) {
    World w = floorWorld();
    RigidBody ball = RigidBody::fromDensity(Sphere{0.1}, 1000.0);
    ball.material.restitution = e;
    const double h0 = 1.0;
    ball.position = Vec3(0, 0, 0.1 + h0);
    const int i = w.addBody(ball);
    const double dt = 1e-4;
    bool bounced = false;
    double peak = 0.0;
    for (int k = 0; k < 40000; ++k) {
      w.step(dt);
      const RigidBody& b = w.body(i);
      if (b.velocity.z() > 0.0) bounced = true;
      if (bounced) {
        peak = std::max(peak, b.position.z() - 0.1);
        if (b.velocity.z() < 0.0) break;
      }
    }
    EXPECT_TRUE(bounced);
    EXPECT_NEAR(peak, e * e * h0, 0.02 * e * e * h0) << "e = " << e;
    std::printf("bounce e=%.1f: peak %.5f, e^2 h0 = %.5f\n", e, peak, e * e * h0);
  }
}

TEST(RigidContact, SlidingBoxStopsAtFrictionDistance) {
  // Coulomb friction decelerates at mu g: stopping distance v0^2 / (2 mu g).
  const double mu = 0.4, v0 = 2.0;
  World w = floorWorld();
  RigidBody box = RigidBody::fromDensity(Box{Vec3(0.25, 0.25, 0.25)}, 500.0);
  box.position = Vec3(0, 0, 0.25);
  box.velocity = Vec3(v0, 0, 0);
  const int i = w.addBody(box);
  w.setPairFriction(i, kWorld, mu);
  const double dt = 1e-3;
  int k = 0;
  for (; k < 5000 && w.body(i).velocity.norm() > 1e-6; ++k) w.step(dt);
  const double expected = v0 * v0 / (2 * mu * kG);
  std::printf("slide: distance %.5f m (expected %.5f), stop time %.4f s (expected %.4f)\n",
              w.body(i).position.x(), expected, k * dt, v0 / (mu * kG));
  EXPECT_NEAR(w.body(i).position.x(), expected, 0.03 * expected);
  EXPECT_NEAR(k * dt, v0 / (mu * kG), 0.03 * v0 / (mu * kG));
  EXPECT_NEAR(w.body(i).position.z(), 0.25, 1e-3);  // did not tip or sink
}

TEST(RigidContact, HeadOnElasticCollisionExchangesVelocities) {
  WorldSettings s;
  s.gravity.setZero();
  World w(s);
  RigidBody a = RigidBody::fromDensity(Sphere{0.5}, 1.0);
  a.material = Material{0.0, 1.0};
  RigidBody b = a;
  a.position = Vec3(0, 0, 0);
  a.velocity = Vec3(1, 0, 0);
  b.position = Vec3(1.5, 0, 0);
  const int ia = w.addBody(a), ib = w.addBody(b);
  const Vec3 p0 = w.body(ia).linearMomentum() + w.body(ib).linearMomentum();
  for (int k = 0; k < 1500; ++k) w.step(1e-3);
  EXPECT_LE(w.body(ia).velocity.norm(), 1e-9);
  EXPECT_LE((w.body(ib).velocity - Vec3(1, 0, 0)).norm(), 1e-9);
  EXPECT_LE((w.body(ia).linearMomentum() + w.body(ib).linearMomentum() - p0).norm(), 1e-12);
}

TEST(RigidContact, UnequalMassElasticCollisionMatchesOneDimensionalFormula) {
  WorldSettings s;
  s.gravity.setZero();
  World w(s);
  RigidBody a = RigidBody::fromMass(Sphere{0.5}, 1.0);
  RigidBody b = RigidBody::fromMass(Sphere{0.5}, 3.0);
  a.material = b.material = Material{0.0, 1.0};
  a.velocity = Vec3(2, 0, 0);
  b.position = Vec3(1.5, 0, 0);
  const int ia = w.addBody(a), ib = w.addBody(b);
  for (int k = 0; k < 1000; ++k) w.step(1e-3);
  // v_a' = (m_a - m_b)/(m_a + m_b) v = -1, v_b' = 2 m_a/(m_a + m_b) v = 1.
  EXPECT_LE((w.body(ia).velocity - Vec3(-1, 0, 0)).norm(), 1e-9);
  EXPECT_LE((w.body(ib).velocity - Vec3(1, 0, 0)).norm(), 1e-9);
}

TEST(RigidContact, SphereRestsOnStaticBox) {
  World w;
  RigidBody table = RigidBody::makeStatic(Box{Vec3(1.0, 1.0, 0.5)});
  table.position = Vec3(0, 0, 0.5);
  w.addBody(table);
  RigidBody ball = RigidBody::fromDensity(Sphere{0.2}, 1000.0);
  ball.position = Vec3(0.3, 0.1, 1.5);
  const int i = w.addBody(ball);
  for (int k = 0; k < 2000; ++k) w.step(1e-3);
  EXPECT_NEAR(w.body(i).position.z(), 1.2, 1e-3);
  EXPECT_NEAR(w.body(i).position.x(), 0.3, 1e-6);
}

TEST(RigidContact, ConvexMeshSettlesOnFloorInsideDomain) {
  World w;
  w.addDomainBox(Vec3(-1, -1, 0), Vec3(1, 1, 2));
  RigidBody tet = RigidBody::fromDensity(makeConvexMesh(testing::tetrahedronMesh(0.4)), 800.0);
  tet.position = Vec3(0.1, 0.0, 1.0);
  tet.angularVelocity = Vec3(1.0, 2.0, 0.5);
  const int i = w.addBody(tet);
  for (int k = 0; k < 4000; ++k) w.step(1e-3);
  const auto& mesh = std::get<ConvexMesh>(w.body(i).shape());
  double lowest = 1e9;
  for (const Vec3& v : mesh.vertices) lowest = std::min(lowest, w.body(i).toWorld(v).z());
  EXPECT_NEAR(lowest, 0.0, 1e-3);
  EXPECT_LE(w.body(i).velocity.norm(), 1e-2);
}

TEST(RigidContact, DomainWallsKeepBodiesInside) {
  World w;
  w.addDomainBox(Vec3(-1, -1, 0), Vec3(1, 1, 2), Material{0.3, 0.5});
  RigidBody ball = RigidBody::fromDensity(Sphere{0.1}, 1000.0);
  ball.position = Vec3(0, 0, 1);
  ball.velocity = Vec3(6, -4, 3);
  RigidBody box = RigidBody::fromDensity(Box{Vec3(0.1, 0.15, 0.2)}, 1000.0);
  box.position = Vec3(0.5, 0.5, 1);
  box.velocity = Vec3(-5, 3, 4);
  box.angularVelocity = Vec3(3, -2, 1);
  const int ib = w.addBody(ball), ix = w.addBody(box);
  double worst = 0.0;  // deepest excursion of the sphere surface / box corners outside
  for (int k = 0; k < 3000; ++k) {
    w.step(1e-3);
    const RigidBody& b = w.body(ib);
    for (int a = 0; a < 3; ++a) {
      const double lo = a == 2 ? 0.0 : -1.0, hi = a == 2 ? 2.0 : 1.0;
      worst = std::max({worst, lo - (b.position[a] - 0.1), b.position[a] + 0.1 - hi});
      for (int c = 0; c < 8; ++c) {
        const Vec3 corner((c & 1) ? 0.1 : -0.1, (c & 2) ? 0.15 : -0.15, (c & 4) ? 0.2 : -0.2);
        const double p = w.body(ix).toWorld(corner)[a];
        worst = std::max({worst, lo - p, p - hi});
      }
    }
  }
  // One step of travel at the entry speed (~8 m/s * 1e-3 s) is the most a contact can overshoot.
  EXPECT_LT(worst, 1e-2);
  std::printf("domain walls: deepest excursion %.3g m\n", worst);
}

TEST(RigidContact, SimulationIsDeterministic) {
  auto run = [] {
    World w;
    w.addDomainBox(Vec3(-1, -1, 0), Vec3(1, 1, 3));
    for (int k = 0; k < 40; ++k) {
      RigidBody b = RigidBody::fromDensity(Sphere{0.1}, 1000.0);
      b.position = Vec3(-0.8 + 0.04 * (k % 10) * 4, -0.5 + 0.1 * (k / 10), 0.2 + 0.25 * k / 10.0);
      b.material.restitution = 0.3;
      w.addBody(b);
    }
    for (int k = 0; k < 300; ++k) w.step(2e-3);
    std::vector<double> out;
    for (const RigidBody& b : w.bodies())
      out.insert(out.end(), b.position.data(), b.position.data() + 3);
    return out;
  };
  EXPECT_EQ(run(), run());
}

}  // namespace
}  // namespace msim::rigid
