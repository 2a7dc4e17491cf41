// Generalized 6-vector interface used by the granular coupling (Narain 2011 eq. 5.23):
// M, M^{-1}, impulses and kinetic energy.
#include "msim/rigid/rigid_body.hpp"

#include <gtest/gtest.h>

#include "msim/core/error.hpp"

namespace msim::rigid {
namespace {

RigidBody tiltedBox() {
  RigidBody b = RigidBody::fromDensity(Box{Vec3(0.5, 1.0, 1.5)}, 2.0);
  b.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()));
  b.position = Vec3(1, 2, 3);
  return b;
}

TEST(RigidBody, MassMatrixTimesInverseIsIdentity) {
  const RigidBody b = tiltedBox();
  EXPECT_LE((b.massMatrix() * b.inverseMassMatrix() - Mat6::Identity()).norm(), 1e-12);
  const Eigen::Matrix3d R = b.rotation();
  EXPECT_LE((b.worldInertia() - R * b.bodyInertia() * R.transpose()).norm(), 1e-12);
}

TEST(RigidBody, ImpulseChangesVelocityByInverseMass) {
  RigidBody b = tiltedBox();
  Vec6 V0;
  V0 << 1, -2, 0.5, 0.3, 0.1, -0.4;
  b.setGeneralizedVelocity(V0);
  Vec6 J;
  J << 3, 1, -2, 0.5, -1, 2;
  b.applyImpulse(J);
  EXPECT_LE((b.generalizedVelocity() - (V0 + b.inverseMassMatrix() * J)).norm(), 1e-12);
  const Vec6 V = b.generalizedVelocity();
  EXPECT_NEAR(b.kineticEnergy(), 0.5 * V.dot(b.massMatrix() * V), 1e-12);
}

TEST(RigidBody, ImpulseAtPointAddsMoment) {
  RigidBody b = tiltedBox();
  const Vec3 p(1.5, 2.0, 3.0), impulse(0, 0, 2);
  b.applyImpulseAt(p, impulse);
  EXPECT_LE((b.velocity - impulse / b.mass()).norm(), 1e-12);
  EXPECT_LE((b.angularMomentum() - (p - b.position).cross(impulse)).norm(), 1e-12);
}

TEST(RigidBody, StaticBodyIgnoresImpulses) {
  RigidBody s = RigidBody::makeStatic(Box{});
  s.applyImpulse(Vec6::Ones());
  EXPECT_EQ(s.generalizedVelocity(), Vec6::Zero());
  EXPECT_TRUE(s.isStatic());
}

TEST(RigidBody, FromMassScalesInertia) {
  const RigidBody b = RigidBody::fromMass(Sphere{0.5}, 3.0);
  EXPECT_DOUBLE_EQ(b.mass(), 3.0);
  EXPECT_NEAR(b.bodyInertia()(0, 0), 0.4 * 3.0 * 0.25, 1e-14);
  EXPECT_THROW(RigidBody::fromMass(Sphere{0.5}, 0.0), InputError);
  EXPECT_THROW(RigidBody::fromMass(Sphere{0.5}, -2.0), InputError);
  EXPECT_THROW(RigidBody::fromDensity(Sphere{0.5}, 0.0), InputError);
}

}  // namespace
}  // namespace msim::rigid
