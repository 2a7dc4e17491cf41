// Particle advection and the shape evolution of eq. 5.42 against exact solutions.
#include "msim/granular/particle_advection.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>

#include "granular_test_support.hpp"
#include "msim/core/interpolation.hpp"

namespace msim::granular {
namespace {

const GridSpec<3> kGrid(Vec3::Constant(-1.0), 0.1, IVec3::Constant(20));

Eigen::Matrix3d someGradient() {
  Eigen::Matrix3d g;
  g << 0.3, 0.5, 0.0, -0.2, 0.1, 0.4, 0.1, 0.0, -0.25;
  return g;
}

TEST(GranularAdvection, JacobianOfALinearFieldIsItsGradient) {
  MacGrid<3> velocity(kGrid);
  const Vec3 b(0.1, -0.2, 0.3);
  test::fillLinear(velocity, someGradient(), b);
  Rng rng(1);
  double worst = 0.0;
  for (int k = 0; k < 1000; ++k) {
    const Vec3 x(rng.uniform(-0.9, 0.9), rng.uniform(-0.9, 0.9), rng.uniform(-0.9, 0.9));
    const VelocitySample s = sampleVelocityAndJacobian(velocity, x);
    worst = std::max(worst, (s.jacobian - someGradient()).cwiseAbs().maxCoeff());
    EXPECT_LE((s.value - (someGradient() * x + b)).cwiseAbs().maxCoeff(), 1e-6);
  }
  std::printf("Jacobian of a linear field: max error %.2g 1/s\n", worst);
  EXPECT_LE(worst, 1e-5);
}

TEST(GranularAdvection, JacobianIsTheDerivativeOfTheCoreInterpolant) {
  // A random field: inside a cell the trilinear interpolant is linear along each axis, so a
  // central difference that stays in the cell is exact up to rounding.
  MacGrid<3> velocity(kGrid);
  Rng rng(2);
  for (int a = 0; a < 3; ++a)
    for (float& u : velocity.component(a).data()) u = float(rng.uniform(-1, 1));
  const double h = 0.01 * kGrid.dx;
  int checked = 0;
  for (int k = 0; k < 2000; ++k) {
    const Vec3 x(rng.uniform(-1.1, 1.1), rng.uniform(-1.1, 1.1), rng.uniform(-1.1, 1.1));
    bool nearPlane = false;  // within h of a sample plane of any face grid
    for (int a = 0; a < 3; ++a) {
      const Vec3 s = velocity.component(a).toSampleSpace(x);
      for (int b = 0; b < 3; ++b) nearPlane |= std::abs(s[b] - std::round(s[b])) < 0.02;
    }
    if (nearPlane) continue;
    ++checked;
    const VelocitySample s = sampleVelocityAndJacobian(velocity, x);
    EXPECT_LE((s.value - sampleLinear<3>(velocity, x)).cwiseAbs().maxCoeff(), 1e-6);
    for (int b = 0; b < 3; ++b) {
      const Vec3 e = Vec3::Unit(b) * h;
      const Vec3 fd = (sampleLinear<3>(velocity, x + e) - sampleLinear<3>(velocity, x - e)) / (2 * h);
      EXPECT_LE((s.jacobian.col(b) - fd).cwiseAbs().maxCoeff(), 2e-3) << "at " << x.transpose() << " axis " << b;
    }
  }
  EXPECT_GT(checked, 300);
}

TEST(GranularAdvection, ShapeInALinearFlowConvergesToTheExactSolutionAtFirstOrder) {
  // v = G x: the particle at the origin stays there and its ellipsoid is mapped by exp(tG), so
  // A(T) = exp(TG) A0 exp(TG)^T. Forward Euler (eq. 5.42) has error O(dt).
  MacGrid<3> velocity(kGrid);
  const Eigen::Matrix3d g = someGradient();
  test::fillLinear(velocity, g);
  Eigen::Matrix3d a0;
  a0 << 4, 1, 0.5, 1, 3, -0.5, 0.5, -0.5, 2;
  a0 *= 1e-4;
  const double t = 1.0;
  const Eigen::Matrix3d exact = test::expm(t * g) * a0 * test::expm(t * g).transpose();
  double previous = 0.0;
  for (int steps : {10, 20, 40, 80, 160}) {
    GranularParticles p;
    p.append(Vecf<3>::Zero(), Vecf<3>::Zero(), 1.0f, toShape(a0), 0);
    for (int k = 0; k < steps; ++k) advectParticles(p, velocity, t / steps);
    const double error = (shapeMatrix(p.shape[0]) - exact).norm() / exact.norm();
    std::printf("shape in v = Gx: %3d steps, relative error %.3e%s\n", steps, error,
                previous > 0 ? (" (ratio " + std::to_string(previous / error) + ")").c_str() : "");
    if (previous > 0) {
      EXPECT_GT(previous / error, 1.8);
      EXPECT_LT(previous / error, 2.2);
    }
    previous = error;
  }
  EXPECT_LT(previous, 5e-3);
}

TEST(GranularAdvection, ProductUpdateStaysPositiveDefiniteUnderStrongCompression) {
  // dt J = -0.9 I: the additive Euler update A + dt (J A + A J^T) = -0.8 A is not a shape any more;
  // F A F^T = 0.01 A is.
  const Eigen::Matrix3d a = 1e-4 * Eigen::Matrix3d::Identity();
  const Eigen::Matrix3d j = -0.9 * Eigen::Matrix3d::Identity();
  EXPECT_TRUE(deformShape(a, j, 1.0).isApprox(0.01 * a));
}

TEST(GranularAdvection, PositionsMoveByCorrectionThenVelocityAndStayInTheDomain) {
  MacGrid<3> velocity(kGrid), displacement(kGrid, 0.05f);
  const Eigen::Matrix3d g = someGradient();
  const Vec3 b(0.2, 0.0, -0.1);
  test::fillLinear(velocity, g, b);
  GranularParticles p;
  const Vec3 x0(0.1, -0.3, 0.4);
  p.append(x0.cast<float>(), Vecf<3>::Zero(), 1.0f, toShape(1e-4 * Eigen::Matrix3d::Identity()), 0);
  p.append(Vecf<3>(0.99f, 0.0f, 0.0f), Vecf<3>::Zero(), 1.0f, toShape(1e-4 * Eigen::Matrix3d::Identity()), 0);
  const double dt = 0.1;
  std::vector<ParticleMotion> motion;
  std::vector<Vec3> correction;
  sampleCorrection(p, displacement, correction);
  advectParticles(p, velocity, dt, correction, &motion);
  const Vec3 corrected = x0 + Vec3::Constant(0.05);
  EXPECT_LE((p.position[0].cast<double>() - (corrected + dt * (g * corrected + b))).norm(), 1e-6);
  // The second one is pushed through x = 1: it stops just inside.
  EXPECT_NEAR(p.position[1][0], 1.0 - kBoundaryEpsilonCells * kGrid.dx, 1e-6);
  EXPECT_LT(p.position[1][0], 1.0f);

  // A point carried by the first particle, 5 mm off its centre: the same correction, then the
  // (here exact) linear flow about the particle.
  const Vec3 r(0.005, -0.002, 0.003);
  const Vec3 carried = carriedPosition(motion[0], x0 + r, dt, kGrid);
  EXPECT_LE((carried - (corrected + r + dt * (g * (corrected + r) + b))).norm(), 1e-6);
}

}  // namespace
}  // namespace msim::granular
