// Render points (ch. 5.6): uniform sampling in ellipsoids, passive advection, reassignment on
// split/merge and resampling.
#include "msim/granular/render_points.hpp"

#include <gtest/gtest.h>

#include <cstdio>

#include "granular_test_support.hpp"
#include "msim/granular/particle_advection.hpp"

namespace msim::granular {
namespace {

constexpr double kPointsDx = 0.1;

double worstDistance(const RenderPoints& points, const GranularParticles& p) {
  double worst = 0.0;
  for (std::size_t k = 0; k < points.size(); ++k) {
    const std::uint32_t i = points.parents()[k];
    worst = std::max(worst, test::mahalanobisDistance(shapeMatrix(p.shape[i]),
                                                points.positions()[k].cast<double>() - p.position[i].cast<double>()));
  }
  return worst;
}

TEST(GranularRenderPoints, SamplesAreUniformInTheEllipsoid) {
  // A uniform solid ellipsoid {d : d^T A^{-1} d <= 1} has mean 0 and second moment A / 5.
  Eigen::Matrix3d a;
  a << 4, 1, 0.5, 1, 3, -0.5, 0.5, -0.5, 2;
  Rng rng(1);
  const int n = 40000;
  Vec3 mean = Vec3::Zero();
  Eigen::Matrix3d moment = Eigen::Matrix3d::Zero();
  for (int k = 0; k < n; ++k) {
    const Vec3 d = sampleInEllipsoid(a, rng);
    EXPECT_LE(test::mahalanobisDistance(a, d), 1.0 + 1e-12);
    mean += d / n;
    moment += d * d.transpose() / n;
  }
  const double momentError = (moment - a / 5).norm() / (a / 5).norm();
  std::printf("ellipsoid sampling: |mean| %.3g, second moment error %.3g\n", mean.norm(), momentError);
  EXPECT_LE(mean.norm(), 0.02);
  EXPECT_LE(momentError, 0.02);
}

TEST(GranularRenderPoints, FollowTheFlowInsideTheirParticlesThroughSplits) {
  const GridSpec<3> grid(Vec3::Zero(), kPointsDx, IVec3::Constant(24));
  const Vec3 centre = Vec3::Constant(1.2);
  Eigen::Matrix3d g;
  g << 0.9, 0.3, 0.0, -0.1, 0.6, 0.1, 0.0, 0.1, 0.4;
  MacGrid<3> velocity(grid);
  test::fillLinear(velocity, g, -g * centre);
  GranularParticles p;
  const std::vector<GranularMaterial> materials{{1600.0, 0.5}};
  seedBox(p, grid, centre.array() - 0.2, centre.array() + 0.2, materials);
  RenderPoints points(16, 5);
  points.sample(p);
  ASSERT_EQ(points.size(), 16 * p.size());
  EXPECT_LE(worstDistance(points, p), 1.0 + kEscapeMargin);

  // First without split/merge: the flow is linear, so the expansion about the particle is the flow
  // itself and each point takes the forward-Euler step x + dt G (x - centre) of the analytic
  // field; and a point moves with the same map F = I + dt G as its particle's ellipsoid
  // (A <- F A F^T), so its Mahalanobis distance does not change and none is resampled.
  const double dt = 0.025;
  std::vector<ParticleMotion> motion;
  double worstEulerError = 0.0;
  std::size_t resampledWithoutSplits = 0;
  for (int step = 0; step < 10; ++step) {
    const std::vector<Vecf<3>> before(points.positions().begin(), points.positions().end());
    advectParticles(p, velocity, dt, {}, &motion);
    resampledWithoutSplits += points.carry(motion, dt, velocity.spec(), p, {});
    for (std::size_t k = 0; k < points.size(); ++k) {
      const Vec3 x = before[k].cast<double>();
      worstEulerError = std::max(worstEulerError, (points.positions()[k].cast<double>() - (x + dt * g * (x - centre))).norm());
    }
  }
  const double worstAfterAdvection = worstDistance(points, p);
  // Then with split/merge every step: points follow a child of their particle.
  SplitMerge splitMerge(particleRadius(kPointsDx));
  std::size_t splits = 0, resampled = 0;
  for (int step = 0; step < 20; ++step) {
    advectParticles(p, velocity, dt, {}, &motion);
    splits += splitMerge.apply(p).splits;
    resampled += points.carry(motion, dt, velocity.spec(), p, splitMerge.successors());
    ASSERT_LE(worstDistance(points, p), 1.0 + kEscapeMargin);
  }
  std::printf("render points: %zu points, worst distance after 10 steps %.6f (%zu resampled), then %zu splits, %zu "
              "resampled\n",
              points.size(), worstAfterAdvection, resampledWithoutSplits, splits, resampled);
  EXPECT_LE(worstAfterAdvection, 1.0 + kEscapeMargin);
  EXPECT_EQ(resampledWithoutSplits, 0u);
  EXPECT_LE(worstEulerError, 1e-5);  // float positions of order 1 m
  EXPECT_GT(splits, 0u);
  EXPECT_EQ(points.size(), 16 * std::size_t(8 * 4 * 4 * 4));  // the total is kept
  // Split children (at +-(sqrt3/2) a e, half as long) do not cover their parent's middle, so about
  // half the points of a split particle are resampled; no other point ever is, and without merges
  // a particle owns at most 16 points.
  EXPECT_GT(resampled, 0u);
  EXPECT_LE(resampled, 16 * splits);
}

TEST(GranularRenderPoints, MergedParticleTakesBothSetsOfPoints) {
  Eigen::Matrix3d thin = Vec3(0.3, 1.0, 1.0).asDiagonal();
  const double r = particleRadius(kPointsDx);
  thin *= r * r;
  GranularParticles p;
  p.append(Vecf<3>(1, 1, 1), Vecf<3>::Zero(), 1.0f, toShape(thin), 0);
  p.append(Vecf<3>(1.0f + float(r), 1, 1), Vecf<3>::Zero(), 1.0f, toShape(thin), 0);
  RenderPoints points(8, 1);
  points.sample(p);
  SplitMerge splitMerge(r);
  // A step without motion: only the merge moves the points' parent.
  std::vector<ParticleMotion> still;
  for (std::size_t i = 0; i < p.size(); ++i)
    still.push_back(ParticleMotion{p.position[i].cast<double>(), Vec3::Zero(), Vec3::Zero(), Eigen::Matrix3d::Zero()});
  ASSERT_EQ(splitMerge.apply(p).merges, 1u);
  // The merged ellipsoid (eq. 5.43) matches the pair's second moment, not their union: the points
  // near the far ends are resampled into it.
  const std::size_t resampled = points.carry(still, 0.01, GridSpec<3>(Vec3::Zero(), 0.1, IVec3::Constant(30)), p,
                                             splitMerge.successors());
  for (std::uint32_t parent : points.parents()) EXPECT_EQ(parent, 0u);
  EXPECT_LT(resampled, points.size());
  EXPECT_LE(worstDistance(points, p), 1.0 + kEscapeMargin);
}

}  // namespace
}  // namespace msim::granular
