// Time integration: free fall against the closed form, torque-free tumbling of an asymmetric box.
#include "msim/rigid/integrator.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "msim/core/error.hpp"
#include "msim/rigid/world.hpp"

namespace msim::rigid {
namespace {

TEST(RigidIntegrator, FreeFallMatchesSymplecticEulerClosedForm) {
  // Symplectic Euler: v_n = v0 - n g dt, x_n = x0 + dt sum_{k=1..n} v_k
  //                 = x0 + v0 t - g t^2/2 - g t dt/2   (t = n dt).
  // So the error against x0 + v0 t - g t^2/2 is exactly -g t dt/2 (first order in dt); we check
  // the discrete closed form to round-off and the continuous one to that derived bound.
  World world;
  RigidBody ball = RigidBody::fromDensity(Sphere{0.1}, 1000.0);
  const Vec3 x0(0.0, 0.0, 10.0), v0(1.0, -0.5, 3.0);
  ball.position = x0;
  ball.velocity = v0;
  const int i = world.addBody(ball);
  const double dt = 1e-3, g = 9.81;
  const int n = 1000;
  for (int k = 0; k < n; ++k) world.step(dt);
  const double t = n * dt;
  const Vec3 gravity(0, 0, -g);
  const Vec3 exact = x0 + v0 * t + 0.5 * gravity * t * t;
  const Vec3 discrete = exact + 0.5 * gravity * t * dt;
  const RigidBody& b = world.body(i);
  EXPECT_LE((b.position - discrete).norm(), 1e-10);
  EXPECT_LE((b.position - exact).norm(), 0.5 * g * t * dt * (1 + 1e-9));
  EXPECT_LE((b.velocity - (v0 + gravity * t)).norm(), 1e-10);
}

TEST(RigidIntegrator, TorqueFreeAsymmetricBoxConservesMomentumAndEnergy) {
  // Spin mostly about the intermediate axis (unstable: the box tumbles), the hardest case
  // for the gyroscopic term.
  RigidBody box = RigidBody::fromDensity(Box{Vec3(0.5, 1.0, 1.5)}, 1.0);
  box.orientation = Eigen::Quaterniond(Eigen::AngleAxisd(0.3, Vec3(1, 1, 0).normalized()));
  box.angularVelocity = box.rotation() * Vec3(0.05, 2.0, 0.05);
  const Vec3 L0 = box.angularMomentum();
  const double E0 = box.kineticEnergy();
  const double dt = 1e-2;
  double maxEnergyError = 0.0, maxMomentumError = 0.0;
  for (int k = 0; k < 1000; ++k) {
    integrateVelocity(box, Vec3::Zero(), dt);
    integratePosition(box, dt);
    maxMomentumError =
        std::max(maxMomentumError, std::abs(box.angularMomentum().norm() - L0.norm()));
    maxEnergyError = std::max(maxEnergyError, std::abs(box.kineticEnergy() - E0));
  }
  EXPECT_LT(maxMomentumError / L0.norm(), 1e-6);
  EXPECT_LT((box.angularMomentum() - L0).norm() / L0.norm(), 1e-6);  // the vector, too
  EXPECT_LT(maxEnergyError / E0, 1e-2);
  std::printf("torque-free box: max |dL|/|L| = %.3g, max |dE|/E = %.3g\n",
              maxMomentumError / L0.norm(), maxEnergyError / E0);
  EXPECT_NEAR(box.orientation.norm(), 1.0, 1e-12);
}

TEST(RigidIntegrator, RejectsNonPositiveStep) {
  World world;
  EXPECT_THROW(world.step(0.0), InputError);
  EXPECT_THROW(world.step(-1e-3), InputError);
}

}  // namespace
}  // namespace msim::rigid
