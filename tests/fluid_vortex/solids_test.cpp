// Particles inside solids are deleted or pushed out along the level set (Selle ch. 3.4.1, Fig. 3.5).
#include <gtest/gtest.h>

#include <cstdio>

#include "msim/core/rng.hpp"
#include "msim/fluid/vortex/vortex_solids.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

const Vec3 kCentre(0.5, 0.5, 0.5);
constexpr double kRadius = 0.25;
double sphere(const Vec3& x) { return (x - kCentre).norm() - kRadius; }

VortexParticles<3> scattered(std::size_t n, std::size_t& inside) {
  VortexParticles<3> particles;
  Rng rng(21);
  inside = 0;
  for (std::size_t p = 0; p < n; ++p) {
    const Vec3 x(rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9), rng.uniform(0.1, 0.9));
    particles.add(x, Eigen::Vector3d(0, 0, double(p)), 0.1, 1.0);  // omega_z tags the particle
    if (sphere(particles.positions().back().cast<double>()) < 0.0) ++inside;
  }
  return particles;
}

}  // namespace

TEST(VortexSolids, ParticlesInsideASolidAreDeleted) {
  std::size_t inside = 0;
  auto particles = scattered(2000, inside);
  EXPECT_EQ(removeVortexParticlesInSolid<3>(particles, sphere), inside);
  EXPECT_EQ(particles.size(), 2000 - inside);
  for (const auto& x : particles.positions()) ASSERT_GE(sphere(x.cast<double>()), 0.0);
  std::printf("  %zu of 2000 were inside the sphere and were deleted\n", inside);
}

TEST(VortexSolids, SampledDistanceGridDeletesTheSame) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 32, IVec3(32, 32, 32));
  Grid<float, 3> phi(spec, IVec3(33, 33, 33), Vec3::Zero());  // nodal, as SmokeSolver's obstacles
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(sphere(phi.position(phi.coord(i))));
  std::size_t inside = 0;
  auto particles = scattered(2000, inside);
  removeVortexParticlesInSolid<3>(particles, phi);
  for (const auto& x : particles.positions()) ASSERT_GE(sampleLinear<3>(phi, x.cast<double>()), 0.0f);
}

TEST(VortexSolids, ParticlesArePushedOutAlongTheLevelSet) {
  std::size_t inside = 0;
  auto particles = scattered(2000, inside);
  const auto before = particles.positions();
  const auto result = pushVortexParticlesOutOfSolid<3>(particles, sphere, 1e-3, 0.01);
  EXPECT_EQ(result.pushed, inside);
  EXPECT_EQ(result.deleted, 0u);
  ASSERT_EQ(particles.size(), 2000u);
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const Vec3 x = particles.positions()[p].cast<double>();
    const Vec3 x0 = before[p].cast<double>();
    ASSERT_GE(sphere(x), 0.0);
    if (sphere(x0) >= 0.0) {
      ASSERT_EQ(particles.positions()[p], before[p]);
    } else {
      ASSERT_NEAR(sphere(x), 0.01, 1e-5);  // on the clearance, straight out along the normal
      ASSERT_LT((x - kCentre).normalized().cross((x0 - kCentre).normalized()).norm(), 1e-4);
    }
  }
  EXPECT_THROW(pushVortexParticlesOutOfSolid<3>(particles, sphere, 0.0, 0.01), std::invalid_argument);
}
