// Particles move with the grid's velocity, trilinearly interpolated (Selle ch. 3.4.1).
#include <gtest/gtest.h>

#include "grid_fields.hpp"
#include "msim/fluid/vortex/vortex_advection.hpp"

using namespace msim;
using namespace msim::fluid;

TEST(VortexAdvection, StayPutAtRestAndTranslateInAUniformFlow) {
  const GridSpec<3> spec(Vec3::Zero(), 0.1, IVec3(20, 20, 20));
  VortexParticles<3> particles;
  particles.add(Vec3(0.31, 0.42, 0.57), Eigen::Vector3d(0, 0, 1), 0.3, 1.0);
  particles.add(Vec3(1.2, 0.8, 1.1), Eigen::Vector3d(1, 0, 0), 0.3, 1.0);
  const auto x0 = particles.positions();

  MacGrid<3> still(spec);
  advectVortexParticles<3>(particles, still, 0.1);
  EXPECT_EQ(particles.positions(), x0);

  const Vec3 U(0.3, -0.2, 0.1);
  const MacGrid<3> uniform = vortex_test::sampledVelocity<3>(spec, [&](const Vec3&) { return U; });
  const double dt = 0.05;
  for (int n = 1; n <= 20; ++n) {
    advectVortexParticles<3>(particles, uniform, dt);
    for (std::size_t p = 0; p < particles.size(); ++p)
      ASSERT_LT((particles.positions()[p].cast<double>() - (x0[p].cast<double>() + n * dt * U)).norm(), 1e-5);
  }
}

TEST(VortexAdvection, ParticlesThatLeaveTheDomainCanBeRemoved) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(10, 10));
  VortexParticles<2> particles;
  particles.add(Vec2(0.95, 0.5), VortexVector<2>(1.0), 0.2, 1.0);
  particles.add(Vec2(0.5, 0.5), VortexVector<2>(-1.0), 0.2, 1.0);
  const MacGrid<2> u = vortex_test::sampledVelocity<2>(spec, [](const Vec2&) { return Vec2(1.0, 0.0); });
  advectVortexParticles<2>(particles, u, 0.1);
  EXPECT_EQ(removeVortexParticlesOutside<2>(particles, spec), 1u);
  ASSERT_EQ(particles.size(), 1u);
  EXPECT_EQ(particles.vorticities()[0][0], -1.0);
}
