// Hinge joint: a compound pendulum about a fixed world axis.
#include "msim/rigid/world.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>
#include <vector>

#include "msim/core/error.hpp"

namespace msim::rigid {
namespace {

// Mean period from upward zero crossings of x (linearly interpolated).
double measurePeriod(World& w, int body, double dt, int steps) {
  std::vector<double> crossings;
  double prev = w.body(body).position.x();
  for (int k = 1; k <= steps; ++k) {
    w.step(dt);
    const double x = w.body(body).position.x();
    if (prev < 0.0 && x >= 0.0) crossings.push_back((k - 1 + prev / (prev - x)) * dt);
    prev = x;
  }
  if (crossings.size() < 2) return 0.0;
  return (crossings.back() - crossings.front()) / (crossings.size() - 1);
}

TEST(RigidHinge, SmallAmplitudePendulumPeriod) {
  // Compound pendulum: T = 2 pi sqrt(I_pivot / (m g d)), I_pivot = I_com + m d^2.
  const double d = 0.8, g = 9.81, theta0 = 0.05, dt = 1e-3;
  World w;
  RigidBody paddle = RigidBody::fromMass(Box{Vec3(0.1, 0.05, 0.3)}, 2.0);
  // Hang below the pivot at the origin, displaced by theta0 about the y axis.
  const Eigen::AngleAxisd tilt(theta0, Vec3::UnitY());
  paddle.position = tilt * Vec3(0, 0, -d);
  paddle.orientation = Eigen::Quaterniond(tilt);
  const int i = w.addBody(paddle);
  w.addHinge(i, Vec3::Zero(), Vec3::UnitY());
  const Vec3 localPivot = paddle.orientation.conjugate() * (Vec3::Zero() - paddle.position);
  const double I = paddle.bodyInertia()(1, 1) + paddle.mass() * d * d;
  const double expected = 2 * std::numbers::pi * std::sqrt(I / (paddle.mass() * g * d));
  const double period = measurePeriod(w, i, dt, 8000);
  EXPECT_NEAR(period, expected, 0.01 * expected);
  std::printf("pendulum: period %.6f s, expected %.6f s\n", period, expected);
  // The pivot stays put and the body stays in its plane.
  const RigidBody& b = w.body(i);
  EXPECT_LE(b.toWorld(localPivot).norm(), 1e-4);
  std::printf("pendulum: pivot drift %.3g m\n", b.toWorld(localPivot).norm());
  EXPECT_LE(std::abs(b.position.y()), 1e-9);
}

TEST(RigidHinge, PaddleWheelSpinsFreelyAboutItsAxleOnly) {
  WorldSettings s;
  s.gravity.setZero();
  World w(s);
  RigidBody wheel = RigidBody::fromDensity(Box{Vec3(0.5, 0.05, 0.1)}, 100.0);
  wheel.position = Vec3(1, 2, 3);
  wheel.angularVelocity = Vec3(0.5, 3.0, -0.2);  // off-axis parts must be removed
  wheel.velocity = Vec3(1, 0, 0);
  const int i = w.addBody(wheel);
  w.addHinge(i, Vec3(1, 2, 3), Vec3::UnitY());
  for (int k = 0; k < 1000; ++k) w.step(1e-3);
  const RigidBody& b = w.body(i);
  EXPECT_LE((b.position - Vec3(1, 2, 3)).norm(), 1e-6);
  EXPECT_LE(std::hypot(b.angularVelocity.x(), b.angularVelocity.z()), 1e-6);
  EXPECT_GT(std::abs(b.angularVelocity.y()), 1.0);
}

TEST(RigidHinge, RejectsBadAxisAndStaticBody) {
  World w;
  const int i = w.addBody(RigidBody::fromDensity(Sphere{0.1}, 1.0));
  EXPECT_THROW(w.addHinge(i, Vec3::Zero(), Vec3::Zero()), InputError);
  const int s = w.addBody(RigidBody::makeStatic(Sphere{0.1}));
  EXPECT_THROW(w.addHinge(s, Vec3::Zero(), Vec3::UnitZ()), InputError);
}

}  // namespace
}  // namespace msim::rigid
