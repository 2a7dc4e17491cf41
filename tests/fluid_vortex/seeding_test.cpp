// Seeding (Selle ch. 3.4.1, 3.5): counts and rates, the four vorticity choices, and bad input.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <functional>
#include <string>

#include "msim/fluid/vortex/vortex_seeding.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

const GridSpec<3> kSeedingDomain(Vec3::Zero(), 0.1, IVec3(10, 20, 10));

VortexSeedSettings<3> boxSettings() {
  VortexSeedSettings<3> s;
  s.regionMin = Vec3(0.2, 0.1, 0.3);
  s.regionMax = Vec3(0.6, 0.5, 0.7);
  s.radius = 0.4;
  s.strength = 2.0;
  s.magnitude = 2e-3;
  return s;
}

std::string messageOf(const std::function<void()>& f) {
  try {
    f();
  } catch (const std::invalid_argument& e) {
    return e.what();
  }
  return "(no exception)";
}

}  // namespace

TEST(VortexSeeding, RandomSeedingFillsTheBoxWithIsotropicDirections) {
  VortexParticles<3> particles;
  Rng rng(42);
  const std::size_t n = 4000;
  EXPECT_EQ(seedVortexParticles<3>(particles, boxSettings(), kSeedingDomain, n, rng), n);
  ASSERT_EQ(particles.size(), n);
  Eigen::Vector3d meanDirection = Eigen::Vector3d::Zero();
  Vec3 meanPosition = Vec3::Zero();
  for (std::size_t p = 0; p < n; ++p) {
    const Vec3 x = particles.positions()[p].cast<double>();
    for (int a = 0; a < 3; ++a) {
      ASSERT_GE(x[a], boxSettings().regionMin[a] - 1e-6);
      ASSERT_LE(x[a], boxSettings().regionMax[a] + 1e-6);
    }
    ASSERT_NEAR(particles.vorticities()[p].norm(), 2e-3, 1e-15);
    EXPECT_EQ(particles.radii()[p], 0.4);
    EXPECT_EQ(particles.strengths()[p], 2.0);
    meanDirection += particles.vorticities()[p] / 2e-3;
    meanPosition += x;
  }
  meanDirection /= n;
  meanPosition /= n;
  // Uniform on the sphere: each component of the mean has standard deviation 1/sqrt(3n) = 0.009.
  EXPECT_LT(meanDirection.norm(), 4.0 / std::sqrt(3.0 * n));
  EXPECT_LT((meanPosition - Vec3(0.4, 0.3, 0.5)).norm(), 0.01);
}

TEST(VortexSeeding, AzimuthalVorticityIsTangentToTheVerticalCylinder) {
  auto s = boxSettings();
  s.vorticity = SeedVorticity::Azimuthal;
  VortexParticles<3> particles;
  Rng rng(4);
  seedVortexParticles<3>(particles, s, kSeedingDomain, 500, rng);
  const Vec3 centre(0.4, 0.3, 0.5);
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const Eigen::Vector3d w = particles.vorticities()[p] / 2e-3;
    Vec3 radial = particles.positions()[p].cast<double>() - centre;
    radial.y() = 0.0;
    ASSERT_NEAR(w.y(), 0.0, 1e-12);                        // horizontal
    ASSERT_NEAR(w.dot(radial.normalized()), 0.0, 1e-6);   // tangent to the cylinder
    ASSERT_GT(Vec3::UnitY().cross(radial).dot(w), 0.0);   // e_up x r sense
  }
}

TEST(VortexSeeding, VerticalVorticityPointsUpOrDownInEqualShares) {
  auto s = boxSettings();
  s.vorticity = SeedVorticity::Vertical;
  VortexParticles<3> particles;
  Rng rng(5);
  seedVortexParticles<3>(particles, s, kSeedingDomain, 1000, rng);
  int up = 0;
  for (std::size_t p = 0; p < particles.size(); ++p) {
    const Eigen::Vector3d w = particles.vorticities()[p];
    ASSERT_EQ(w.x(), 0.0);
    ASSERT_EQ(w.z(), 0.0);
    ASSERT_NEAR(std::abs(w.y()), 2e-3, 1e-15);
    up += w.y() > 0.0;
  }
  EXPECT_NEAR(up, 500, 60);  // binomial(1000, 1/2): 3.8 standard deviations
}

TEST(VortexSeeding, LocalFlowTakesTheGridVorticityAndSkipsCalmRegions) {
  Vorticity<3> flow(kSeedingDomain);
  for (std::size_t i = 0; i < flow.count(); ++i)
    flow[i] = flow.position(flow.coord(i)).x() < 0.45 ? Eigen::Vector3f(0, 0, 3.0f) : Eigen::Vector3f::Zero();
  auto s = boxSettings();
  s.regionMin.x() = 0.1;
  s.regionMax.x() = 0.3;  // all of it where the flow turns about +z at 3/s
  s.vorticity = SeedVorticity::LocalFlow;
  s.minimumFlowVorticity = 0.1;
  VortexParticles<3> particles;
  Rng rng(8);
  EXPECT_EQ(seedVortexParticles<3>(particles, s, kSeedingDomain, 100, rng, &flow), 100u);
  for (const auto& w : particles.vorticities()) ASSERT_LT((w - Eigen::Vector3d(0, 0, 3)).norm(), 1e-6);

  s.regionMin.x() = 0.6;
  s.regionMax.x() = 0.9;  // calm
  EXPECT_EQ(seedVortexParticles<3>(particles, s, kSeedingDomain, 100, rng, &flow), 0u);
  EXPECT_THROW(seedVortexParticles<3>(particles, s, kSeedingDomain, 1, rng), std::invalid_argument);  // no grid given
}

TEST(VortexSeeding, EmitterKeepsItsRateOverUnevenSteps) {
  VortexEmitter<3> emitter(boxSettings(), kSeedingDomain, 1200.0, 99);
  VortexParticles<3> particles;
  double t = 0.0;
  for (int step = 0; step < 37; ++step) {
    const double dt = 0.004 + 0.0003 * (step % 5);
    const std::size_t added = emitter.emit(particles, dt);
    t += dt;
    ASSERT_NEAR(double(particles.size()), std::floor(1200.0 * t), 1.0) << "step " << step << " added " << added;
  }
  std::printf("  %zu particles after %.4f s at 1200/s (%.1f expected)\n", particles.size(), t, 1200.0 * t);
  // The same seed and steps give the same particles.
  VortexEmitter<3> again(boxSettings(), kSeedingDomain, 1200.0, 99);
  VortexParticles<3> copy;
  for (int step = 0; step < 37; ++step) again.emit(copy, 0.004 + 0.0003 * (step % 5));
  EXPECT_EQ(copy.positions(), particles.positions());
}

TEST(VortexSeeding, BadInputIsRejectedNamingTheField) {
  auto outside = boxSettings();
  outside.regionMax.x() = 1.5;  // the domain ends at x = 1
  EXPECT_NE(messageOf([&] { outside.validate(kSeedingDomain, "smoke.vortex_particles.seed"); })
                .find("smoke.vortex_particles.seed.region"),
            std::string::npos);
  // A box drawn to the domain's bounds as written passes, however dx rounds (4.8 / 96 * 32 < 1.6).
  const GridSpec<3> river(Vec3::Zero(), 4.8 / 96, IVec3(96, 24, 32));
  auto toTheWall = boxSettings();
  toTheWall.regionMin = Vec3::Zero();
  toTheWall.regionMax = Vec3(0.5, 0.4, 1.6);
  EXPECT_NO_THROW(toTheWall.validate(river));
  auto inverted = boxSettings();
  inverted.regionMin.y() = 0.8;
  EXPECT_NE(messageOf([&] { inverted.validate(kSeedingDomain); }).find("exceeds"), std::string::npos);
  auto radius = boxSettings();
  radius.radius = -0.1;
  EXPECT_NE(messageOf([&] { radius.validate(kSeedingDomain, "s"); }).find("s.radius"), std::string::npos);
  auto strength = boxSettings();
  strength.strength = -1.0;
  EXPECT_NE(messageOf([&] { strength.validate(kSeedingDomain, "s"); }).find("s.strength"), std::string::npos);
  EXPECT_THROW(VortexEmitter<3>(boxSettings(), kSeedingDomain, -5.0, 1), std::invalid_argument);

  VortexParticles<3> particles;
  EXPECT_THROW(particles.add(Vec3::Zero(), Eigen::Vector3d::UnitX(), -0.1, 1.0), std::invalid_argument);
  EXPECT_THROW(particles.add(Vec3::Zero(), Eigen::Vector3d::UnitX(), 0.0, 1.0), std::invalid_argument);
  EXPECT_THROW(particles.add(Vec3::Zero(), Eigen::Vector3d::UnitX(), 0.1, -1.0), std::invalid_argument);
  EXPECT_THROW(particles.add(Vec3::Zero(), Eigen::Vector3d(NAN, 0, 0), 0.1, 1.0), std::invalid_argument);
  EXPECT_EQ(particles.size(), 0u);
  EXPECT_NE(messageOf([&] { particles.add(Vec3::Zero(), Eigen::Vector3d::UnitX(), -0.1, 1.0); }).find("radius"),
            std::string::npos);
}
