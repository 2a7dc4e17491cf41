// Vortex stretching with rescale (Selle ch. 3.4.1): |omega_p| is kept, and the direction follows
// the analytic solution of d omega/dt = (omega . grad) u.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "grid_fields.hpp"
#include "msim/core/rng.hpp"
#include "msim/fluid/vortex/velocity_gradient.hpp"
#include "msim/fluid/vortex/vortex_stretching.hpp"

using namespace msim;
using namespace msim::fluid;

TEST(VelocityGradient, IsExactForALinearField) {
  const GridSpec<3> spec(Vec3(-0.2, 0.1, 0.0), 0.05, IVec3(10, 12, 9));
  Eigen::Matrix3d A;
  A << 0.3, -1.2, 0.5, 0.7, 0.1, -0.4, 0.2, 0.9, -0.4;
  const MacGrid<3> u = vortex_test::sampledVelocity<3>(spec, [&](const Vec3& x) { return Vec3(A * x + Vec3(1, 2, 3)); });
  for (const Vec3& x : {Vec3(0.0, 0.3, 0.2), Vec3(-0.19, 0.69, 0.44), Vec3(0.27, 0.12, 0.01)})
    EXPECT_LT((velocityGradientAt<3>(u, x) - A).norm(), 1e-5) << x.transpose();
}

// Many steps in a field with a positive strain eigenvalue: without the rescale omega would grow
// as e^{lambda t}; with it, each |omega_p| stays at its start to 1e-12 relative.
TEST(VortexStretching, RescaleKeepsEachMagnitudeTo1e12) {
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3(10, 10, 10));
  Eigen::Matrix3d A;
  A << 2.0, 0.5, -0.3, 0.1, -1.0, 0.8, 0.6, -0.2, -1.0;  // trace free: divergence-free
  const MacGrid<3> u = vortex_test::sampledVelocity<3>(spec, [&](const Vec3& x) { return Vec3(A * x); });

  VortexParticles<3> particles;
  Rng rng(1);
  std::vector<double> start;
  for (int p = 0; p < 64; ++p) {
    const Eigen::Vector3d w = rng.uniform(1e-3, 5e-2) * Eigen::Vector3d(rng.normal(), rng.normal(), rng.normal()).normalized();
    particles.add(Vec3(rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9)), w, 0.3, 1.0);
    start.push_back(w.norm());
  }
  Eigen::Vector3d free = particles.vorticities()[0];
  for (int step = 0; step < 2000; ++step) {
    stretchVortexParticles<3>(particles, u, 0.01);
    free += 0.01 * velocityGradientAt<3>(u, particles.positions()[0].cast<double>()) * free;
  }
  double worst = 0.0;
  for (std::size_t p = 0; p < particles.size(); ++p)
    worst = std::max(worst, std::abs(particles.vorticities()[p].norm() - start[p]) / start[p]);
  std::printf("  2000 steps: max relative change of |omega_p| %.2e (unrescaled grew x%.2e)\n", worst, free.norm() / start[0]);
  EXPECT_LT(worst, 1e-12);
  EXPECT_GT(free.norm() / start[0], 1e3);
}

// u = (gamma y, 0, 0): (omega . grad) u = gamma omega_y e_x, so omega(t) = omega_0 + gamma t
// omega_y0 e_x. The rescale only changes the length, the ODE is linear, so the direction after the
// steps is that of the analytic solution.
TEST(VortexStretching, PureShearTurnsOmegaAsTheAnalyticSolution) {
  const double gamma = 1.5, dt = 0.02;
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3(10, 10, 10));
  const MacGrid<3> u = vortex_test::sampledVelocity<3>(spec, [&](const Vec3& x) { return Vec3(gamma * x.y(), 0, 0); });
  const Eigen::Vector3d omega0 = 3e-2 * Eigen::Vector3d(0.2, 0.9, -0.4).normalized();
  VortexParticles<3> particles;
  particles.add(Vec3(0.5, 0.5, 0.5), omega0, 0.3, 1.0);
  double worstAngle = 0.0;
  for (int n = 1; n <= 200; ++n) {
    stretchVortexParticles<3>(particles, u, dt);
    const Eigen::Vector3d exact = omega0 + gamma * (n * dt) * omega0.y() * Eigen::Vector3d::UnitX();
    const Eigen::Vector3d w = particles.vorticities()[0];
    worstAngle = std::max(worstAngle, w.normalized().cross(exact.normalized()).norm());
    ASSERT_NEAR(w.norm(), omega0.norm(), 1e-12 * omega0.norm());
  }
  const Eigen::Vector3d final = particles.vorticities()[0].normalized();
  std::printf("  after t = 4: omega_hat = (%.4f, %.4f, %.4f), max sin(angle to analytic) %.2e\n", final.x(), final.y(),
              final.z(), worstAngle);
  EXPECT_LT(worstAngle, 1e-6);  // float face velocities: G is exact to ~1e-7
  EXPECT_GT(final.x(), 0.9);    // it has turned towards the shear direction
}

TEST(VortexStretching, DoesNothingIn2D) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(8, 8));
  const MacGrid<2> u = vortex_test::sampledVelocity<2>(spec, [](const Vec2& x) { return Vec2(2.0 * x.y(), x.x()); });
  VortexParticles<2> particles;
  particles.add(Vec2(0.4, 0.4), VortexVector<2>(0.7), 0.2, 1.0);
  stretchVortexParticles<2>(particles, u, 0.1);
  EXPECT_EQ(particles.vorticities()[0][0], 0.7);
}
