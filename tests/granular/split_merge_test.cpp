// Split and merge (ch. 5.4.1): validity, exact conservation and the eq. 5.43 round trip.
#include "msim/granular/split_merge.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include <Eigen/Eigenvalues>
#include <Eigen/Geometry>

#include "granular_test_support.hpp"
#include "msim/granular/particle_advection.hpp"

namespace msim::granular {
namespace {

constexpr double kSplitDx = 0.1;
const double kR = particleRadius(kSplitDx);

// Semi-axes relative to r, ascending.
Vec3 semiAxesOverR(const ParticleShape& s) {
  return Eigen::SelfAdjointEigenSolver<Eigen::Matrix3d>(shapeMatrix(s)).eigenvalues().cwiseSqrt() / kR;
}

void expectAllValid(const GranularParticles& p, double tolerance = 1e-4) {
  for (std::size_t i = 0; i < p.size(); ++i) {
    const Vec3 axes = semiAxesOverR(p.shape[i]);
    EXPECT_GE(axes[0], (1 - tolerance) / std::sqrt(2.0)) << "particle " << i;
    EXPECT_LE(axes[2], (1 + tolerance) * std::sqrt(2.0)) << "particle " << i;
  }
}

void expectConserved(const test::Totals& before, const test::Totals& after, double scale) {
  EXPECT_LE(std::abs(after.mass - before.mass) / before.mass, 1e-6);
  EXPECT_LE((after.momentum - before.momentum).norm() / before.mass, 1e-6);  // |v| <= ~1 m/s
  EXPECT_LE((after.centreOfMass() - before.centreOfMass()).norm() / scale, 1e-6);
}

TEST(GranularSplitMerge, ValidityIsTheSemiAxisRange) {
  const auto diag = [](double a, double b, double c) { return Vec3(a * a, b * b, c * c).asDiagonal().toDenseMatrix(); };
  EXPECT_TRUE(isValidShape(diag(kR, kR, kR), kR));
  EXPECT_TRUE(isValidShape(diag(0.71 * kR, 1.41 * kR, kR), kR));
  EXPECT_FALSE(isValidShape(diag(0.70 * kR, kR, kR), kR));
  EXPECT_FALSE(isValidShape(diag(kR, 1.42 * kR, kR), kR));
  EXPECT_THROW(SplitMerge(0.0), std::invalid_argument);
  EXPECT_THROW(SplitMerge(kR, 4), std::invalid_argument);
}

TEST(GranularSplitMerge, SplitThenMergeOfTheChildrenGivesBackTheParticle) {
  // A particle stretched to 1.6 r along a tilted axis.
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d a = rotation * Vec3(1.6 * 1.6, 1.1 * 1.1, 0.9 * 0.9).asDiagonal() * rotation.transpose() * kR * kR;
  GranularParticles p;
  p.append(Vecf<3>(0.3f, -0.2f, 0.5f), Vecf<3>(1.0f, -2.0f, 0.5f), 0.25f, toShape(a), 3);
  const GranularParticles original = p;
  SplitMerge splitMerge(kR);
  const SplitMergeStats stats = splitMerge.apply(p);
  ASSERT_EQ(stats.splits, 1u);
  ASSERT_EQ(p.size(), 2u);
  EXPECT_EQ(splitMerge.successors()[0].begin, 0u);
  EXPECT_EQ(splitMerge.successors()[0].count, 2u);
  expectAllValid(p);
  // Children: half the mass, the same velocity and material, the long semi-axis halved.
  for (int c = 0; c < 2; ++c) {
    EXPECT_EQ(p.mass[c], 0.125f);
    EXPECT_EQ(p.velocity[c], original.velocity[0]);
    EXPECT_EQ(p.material[c], 3);
    EXPECT_NEAR(semiAxesOverR(p.shape[c])[0], 0.8, 1e-5);
  }
  const MergedParticle k = mergeParticles(p.position[0].cast<double>(), p.velocity[0].cast<double>(), p.mass[0],
                                          shapeMatrix(p.shape[0]), p.position[1].cast<double>(),
                                          p.velocity[1].cast<double>(), p.mass[1], shapeMatrix(p.shape[1]));
  const double shapeError = (k.shape - a).norm() / a.norm();
  const double positionError = (k.position - original.position[0].cast<double>()).norm() / kR;
  std::printf("split + merge round trip: shape %.2g, position %.2g (relative)\n", shapeError, positionError);
  EXPECT_LE(shapeError, 1e-6);  // float storage of the children
  EXPECT_LE(positionError, 1e-5);
  EXPECT_EQ(k.mass, 0.25);
  EXPECT_LE((k.velocity - original.velocity[0].cast<double>()).norm(), 1e-7);
}

TEST(GranularSplitMerge, IsotropicGrowthSplitsIntoEightValidChildren) {
  GranularParticles p;
  p.append(Vecf<3>::Zero(), Vecf<3>::Zero(), 1.0f, toShape(1.5 * 1.5 * kR * kR * Eigen::Matrix3d::Identity()), 0);
  SplitMerge splitMerge(kR);
  const SplitMergeStats stats = splitMerge.apply(p);
  EXPECT_EQ(stats.children, 8u);
  ASSERT_EQ(p.size(), 8u);
  expectAllValid(p);
  EXPECT_LE(test::totals(p).centreOfMass().norm(), 1e-8);
  // With at most one level allowed the split is refused (its children would be invalid).
  GranularParticles q;
  q.append(Vecf<3>::Zero(), Vecf<3>::Zero(), 1.0f, toShape(1.5 * 1.5 * kR * kR * Eigen::Matrix3d::Identity()), 0);
  EXPECT_EQ(SplitMerge(kR, 1).apply(q).splits, 0u);
  EXPECT_EQ(q.size(), 1u);
}

TEST(GranularSplitMerge, DivergingCloudIsSplitStaysValidAndConserves) {
  // A seeded block in v = G (x - c) with G symmetric positive definite: every ellipsoid grows.
  const GridSpec<3> grid(Vec3::Zero(), kSplitDx, IVec3::Constant(24));
  const Vec3 centre = Vec3::Constant(1.2);
  Eigen::Matrix3d g;
  g << 0.9, 0.2, 0.0, 0.2, 0.6, 0.1, 0.0, 0.1, 0.4;
  MacGrid<3> velocity(grid);
  test::fillLinear(velocity, g, -g * centre);
  GranularParticles p;
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  seedBox(p, grid, centre.array() - 0.3, centre.array() + 0.3, materials);
  test::randomVelocities(p, 11);
  const std::size_t initial = p.size();
  SplitMerge splitMerge(kR);
  SplitMergeStats total;
  for (int step = 0; step < 40; ++step) {
    advectParticles(p, velocity, 0.025);
    const test::Totals before = test::totals(p);
    const SplitMergeStats s = splitMerge.apply(p);
    total.splits += s.splits;
    total.children += s.children;
    total.merges += s.merges;
    expectConserved(before, test::totals(p), 1.0);
    expectAllValid(p);
    if (HasFailure()) break;
  }
  std::printf("diverging cloud: %zu -> %zu particles, %zu splits (%zu children), %zu merges\n", initial, p.size(),
              total.splits, total.children, total.merges);
  EXPECT_GT(total.splits, initial / 2);
}

// A particle stretched along one axis every step (as in a shear layer that persists) splits only
// while its children stay at or above the minimum mass, and the total mass is kept exactly.
TEST(GranularSplitMerge, NoSplitBelowTheMinimumChildMass) {
  GranularParticles p;
  p.append(Vecf<3>(1.0f, 1.0f, 1.0f), Vecf<3>::Zero(), 1.0f, toShape(kR * kR * Eigen::Matrix3d::Identity()), 0);
  SplitMerge splitMerge(kR);
  splitMerge.setMinimumChildMass(1.0 / 16.0);
  for (int step = 0; step < 12; ++step) {
    // Stretch every particle twofold along x.
    for (std::size_t i = 0; i < p.size(); ++i) {
      Eigen::Matrix3d a = shapeMatrix(p.shape[i]);
      a(0, 0) *= 4.0;
      p.shape[i] = toShape(a);
    }
    splitMerge.apply(p);
  }
  double mass = 0.0, lightest = 1.0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    mass += p.mass[i];
    lightest = std::min(lightest, static_cast<double>(p.mass[i]));
  }
  EXPECT_EQ(mass, 1.0);
  EXPECT_EQ(lightest, 1.0 / 16.0);  // four halvings, then no more
  EXPECT_EQ(p.size(), 16u);
}

TEST(GranularSplitMerge, CompressedCloudMergesValidlyAndConserves) {
  // Uniaxial compression v = (-k (x - c), 0, 0): ellipsoids flatten along x and merge with their
  // (now close) neighbours along x.
  const GridSpec<3> grid(Vec3::Zero(), kSplitDx, IVec3::Constant(24));
  const Vec3 centre = Vec3::Constant(1.2);
  Eigen::Matrix3d g = Eigen::Matrix3d::Zero();
  g(0, 0) = -1.0;
  MacGrid<3> velocity(grid);
  test::fillLinear(velocity, g, -g * centre);
  GranularParticles p;
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  seedBox(p, grid, centre.array() - 0.3, centre.array() + 0.3, materials);
  test::randomVelocities(p, 12);
  const std::size_t initial = p.size();
  SplitMerge splitMerge(kR);
  std::size_t merges = 0;
  for (int step = 0; step < 30; ++step) {
    advectParticles(p, velocity, 0.025);
    const test::Totals before = test::totals(p);
    const std::size_t n = p.size();
    const SplitMergeStats s = splitMerge.apply(p);
    merges += s.merges;
    EXPECT_EQ(p.size(), n - s.mergedAway + s.children - s.splits);
    expectConserved(before, test::totals(p), 1.0);
    // Every merged particle is valid; the successors map both members to it.
    for (std::size_t i = 0; i < n; ++i) EXPECT_LT(splitMerge.successors()[i].begin, p.size());
    if (HasFailure()) break;
  }
  std::printf("compressed cloud: %zu -> %zu particles, %zu merges\n", initial, p.size(), merges);
  EXPECT_GT(merges, initial / 4);
}

TEST(GranularSplitMerge, OnlyParticlesOfTheSameMaterialMerge) {
  const Eigen::Matrix3d flat = Vec3(0.5 * kR * kR, kR * kR, kR * kR).asDiagonal();
  GranularParticles p;
  p.append(Vecf<3>(0, 0, 0), Vecf<3>::Zero(), 1.0f, toShape(flat), 0);
  p.append(Vecf<3>(float(kR), 0, 0), Vecf<3>::Zero(), 1.0f, toShape(flat), 1);
  p.shape[0][0] = p.shape[1][0] = float(0.3 * kR * kR);  // too thin
  GranularParticles q = p;
  EXPECT_EQ(SplitMerge(kR).apply(p).merges, 0u);
  q.material[1] = 0;
  SplitMerge splitMerge(kR);
  EXPECT_EQ(splitMerge.apply(q).merges, 1u);
  ASSERT_EQ(q.size(), 1u);
  EXPECT_EQ(splitMerge.successors()[1].begin, 0u);
  EXPECT_NEAR(q.position[0][0], 0.5 * kR, 1e-8);
  EXPECT_EQ(q.mass[0], 2.0f);
  expectAllValid(q);
}

TEST(GranularSplitMerge, MergesWithTheNearestPartnerThatGivesAValidParticle) {
  // Particle 0 is too thin along y (semi-axis r/2). Its nearest neighbour, 0.8 r away along x, is as
  // thin, so merging the two leaves the thin axis (r/2): invalid. The next one, a round particle
  // 1.2 r above, gives a valid merge (semi-axes squared r^2 and 0.985 r^2 by eq. 5.43).
  const double r2 = kR * kR;
  const Eigen::Matrix3d thin = Vec3(r2, 0.25 * r2, r2).asDiagonal(), round = Eigen::Matrix3d::Identity() * r2;
  GranularParticles p;
  p.append(Vecf<3>(0, 0, 0), Vecf<3>(1, 0, 0), 1.0f, toShape(thin), 0);
  p.append(Vecf<3>(float(0.8 * kR), 0, 0), Vecf<3>::Zero(), 1.0f, toShape(thin), 0);
  p.append(Vecf<3>(0, float(1.2 * kR), 0), Vecf<3>::Zero(), 1.0f, toShape(round), 0);
  const MergedParticle withNearest = mergeParticles(Vec3::Zero(), Vec3::Zero(), 1.0, thin, Vec3(0.8 * kR, 0, 0),
                                                    Vec3::Zero(), 1.0, thin);
  ASSERT_FALSE(isValidShape(withNearest.shape, kR));
  const test::Totals before = test::totals(p);
  SplitMerge splitMerge(kR);
  EXPECT_EQ(splitMerge.apply(p).merges, 1u);
  ASSERT_EQ(p.size(), 2u);
  // 0 and 2 became the particle at slot 0; 1 (whose partners 0 and 2 were taken) waits.
  EXPECT_EQ(splitMerge.successors()[0].begin, 0u);
  EXPECT_EQ(splitMerge.successors()[2].begin, 0u);
  EXPECT_NEAR(p.position[0][1], 0.6 * kR, 1e-7);
  EXPECT_NEAR(p.velocity[0][0], 0.5, 1e-7);
  expectConserved(before, test::totals(p), kR);
  const Vec3 axes = semiAxesOverR(p.shape[0]);
  EXPECT_NEAR(axes[0] * axes[0], 0.985, 1e-5);
  EXPECT_NEAR(axes[2] * axes[2], 1.0, 1e-5);
}

TEST(GranularSplitMerge, ParticlesSquashedInEveryDirectionMergeAsAGroup) {
  // Seven particles of semi-axes 0.59 r (A = 0.35 r^2 I, too small along every axis): one at the
  // origin and six 0.9 r away along +-x, +-y, +-z. A merge grows the shape only along the
  // separation, so no pair is valid (eq. 5.43: 0.35 + 0.81 / 4 along it, 0.35 across); the seven
  // together are, A = (0.35 + 2 * 0.81 / 7) r^2 I.
  const double r2 = kR * kR, d = 0.9 * kR;
  const Eigen::Matrix3d small = Eigen::Matrix3d::Identity() * 0.35 * r2;
  GranularParticles p;
  p.append(Vecf<3>::Zero(), Vecf<3>(0, 0, 0.7f), 1.0f, toShape(small), 0);
  for (int a = 0; a < 3; ++a)
    for (const double sign : {1.0, -1.0}) {
      Vecf<3> x = Vecf<3>::Zero();
      x[a] = static_cast<float>(sign * d);
      p.append(x, Vecf<3>::Zero(), 1.0f, toShape(small), 0);
    }
  const test::Totals before = test::totals(p);
  SplitMerge splitMerge(kR);
  const SplitMergeStats stats = splitMerge.apply(p);
  EXPECT_EQ(stats.merges, 1u);
  EXPECT_EQ(stats.mergedAway, 6u);
  ASSERT_EQ(p.size(), 1u);
  for (const auto& s : splitMerge.successors()) EXPECT_EQ(s.begin, 0u);
  expectConserved(before, test::totals(p), kR);
  const Eigen::Matrix3d expected = Eigen::Matrix3d::Identity() * (0.35 + 2.0 * 0.81 / 7.0) * r2;
  EXPECT_LT((shapeMatrix(p.shape[0]) - expected).norm() / expected.norm(), 1e-6);
  expectAllValid(p);
}

TEST(GranularSplitMerge, ParticleNoSplitOrMergeCanFixIsBroughtIntoTheBand) {
  // A sheared particle, too long (2 r) and too thin (0.45 r) at once, axes rotated off the grid: its
  // split children would be as thin, and it has no neighbour to merge with. It keeps its mass,
  // velocity, position and axes; its semi-axes are clamped into [0.8 r, 1.25 r].
  const double r2 = kR * kR;
  const Eigen::Matrix3d axes = Eigen::AngleAxisd(0.4, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Eigen::Matrix3d sheared = axes * Vec3(4.0 * r2, 0.2 * r2, r2).asDiagonal() * axes.transpose();
  GranularParticles p;
  p.append(Vecf<3>(0.1f, 0.2f, 0.3f), Vecf<3>(1, -2, 3), 0.5f, toShape(sheared), 0);
  const GranularParticles before = p;
  SplitMerge splitMerge(kR);
  const SplitMergeStats stats = splitMerge.apply(p);
  EXPECT_EQ(stats.splits + stats.merges, 0u);
  EXPECT_EQ(stats.regularized, 1u);
  ASSERT_EQ(p.size(), 1u);
  EXPECT_EQ(p.position[0], before.position[0]);
  EXPECT_EQ(p.velocity[0], before.velocity[0]);
  EXPECT_EQ(p.mass[0], before.mass[0]);
  const Eigen::Matrix3d expected = axes * Vec3(1.5625 * r2, 0.64 * r2, r2).asDiagonal() * axes.transpose();
  EXPECT_LT((shapeMatrix(p.shape[0]) - expected).norm() / expected.norm(), 1e-5);
  expectAllValid(p);
}

TEST(GranularSplitMerge, NoMergeAboveTheMaximumMass) {
  // Two too-thin particles whose pair is valid (as in OnlyParticlesOfTheSameMaterialMerge), mass
  // 1 each: merged under a limit of 2 (float masses at exactly the limit pass), regularized in place
  // under 1.5.
  const Eigen::Matrix3d thin = Vec3(0.3 * kR * kR, kR * kR, kR * kR).asDiagonal();
  GranularParticles p;
  p.append(Vecf<3>(0, 0, 0), Vecf<3>::Zero(), 1.0f, toShape(thin), 0);
  p.append(Vecf<3>(float(kR), 0, 0), Vecf<3>::Zero(), 1.0f, toShape(thin), 0);
  GranularParticles q = p;
  SplitMerge atLimit(kR);
  atLimit.setMaximumMergedMass({2.0});
  EXPECT_EQ(atLimit.apply(p).merges, 1u);
  EXPECT_EQ(p.size(), 1u);
  SplitMerge belowLimit(kR);
  belowLimit.setMaximumMergedMass({1.5});
  const SplitMergeStats stats = belowLimit.apply(q);
  EXPECT_EQ(stats.merges, 0u);
  EXPECT_EQ(stats.regularized, 2u);
  ASSERT_EQ(q.size(), 2u);
  expectAllValid(q);
}

TEST(GranularSplitMerge, DeterministicAcrossRuns) {
  const GridSpec<3> grid(Vec3::Zero(), kSplitDx, IVec3::Constant(12));
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  GranularParticles a;
  seedBox(a, grid, Vec3::Constant(0.3), Vec3::Constant(0.9), materials);
  Rng rng(4);
  for (ParticleShape& s : a.shape) s[0] *= float(rng.uniform(0.2, 3.0));  // some too thin, some too long
  GranularParticles b = a;
  SplitMerge first(kR), second(kR);
  first.apply(a);
  second.apply(b);
  EXPECT_EQ(a.position, b.position);
  EXPECT_EQ(a.shape, b.shape);
}

}  // namespace
}  // namespace msim::granular
