// The kernels of Selle ch. 3.5 against closed forms: the clamped Gaussian holds the mass of a unit
// Gaussian inside one sigma (erf(1/sqrt2) - sqrt(2/pi) e^{-1/2} in 3D, 1 - e^{-1/2} in 2D), the
// tent unit mass; the single-particle force is the printed F_p = eps xi (N_p x omega_p).
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "msim/fluid/vortex/vortex_kernel.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

// integral over the ball of xi, by the radial rule on 20000 midpoints.
template <int D>
double kernelMass(VortexKernel kernel, double r) {
  const int n = 20000;
  double mass = 0.0;
  for (int i = 0; i < n; ++i) {
    const double s = (i + 0.5) * r / n;
    const double shell = D == 3 ? 4.0 * std::numbers::pi * s * s : 2.0 * std::numbers::pi * s;
    mass += vortexKernelValue<D>(kernel, s, r) * shell * (r / n);
  }
  return mass;
}

}  // namespace

TEST(VortexKernel, ClampedGaussianKeepsTheGaussianMassWithinOneSigma) {
  const double inside3 = std::erf(1.0 / std::sqrt(2.0)) - std::sqrt(2.0 / std::numbers::pi) * std::exp(-0.5);
  EXPECT_NEAR(kernelMass<3>(VortexKernel::ClampedGaussian, 0.37), inside3, 1e-6);  // 0.1987
  EXPECT_NEAR(kernelMass<2>(VortexKernel::ClampedGaussian, 0.37), 1.0 - std::exp(-0.5), 1e-6);  // 0.3935
  EXPECT_NEAR(kernelMass<3>(VortexKernel::Tent, 0.37), 1.0, 1e-6);
  EXPECT_NEAR(kernelMass<2>(VortexKernel::Tent, 0.37), 1.0, 1e-6);
  // The printed normalisation at the centre, and the cut-off just past r.
  EXPECT_DOUBLE_EQ(vortexKernelValue<3>(VortexKernel::ClampedGaussian, 0.0, 2.0), 1.0 / (8.0 * std::pow(2.0 * std::numbers::pi, 1.5)));
  EXPECT_GT(vortexKernelValue<3>(VortexKernel::ClampedGaussian, 2.0, 2.0), 0.0);
  EXPECT_EQ(vortexKernelValue<3>(VortexKernel::ClampedGaussian, 2.0 + 1e-12, 2.0), 0.0);
}

TEST(VortexKernel, ForceIsEpsXiTimesTowardsParticleCrossOmega) {
  const Eigen::Vector3d omega(0.0, 0.0, 3.0);
  const double r = 1.0, eps = 0.5;
  // At d = +0.5 e_x, N_p = -e_x and N_p x e_z = +e_y: counter-clockwise about +omega.
  const Vec3 F = vortexParticleForce<3>(VortexKernel::ClampedGaussian, Vec3(0.5, 0, 0), omega, r, eps);
  const double xi = std::exp(-0.125) / std::pow(2.0 * std::numbers::pi, 1.5);
  EXPECT_NEAR(F.x(), 0.0, 1e-15);
  EXPECT_NEAR(F.y(), eps * xi * 3.0, 1e-15);
  EXPECT_NEAR(F.z(), 0.0, 1e-15);
  EXPECT_EQ(vortexParticleForce<3>(VortexKernel::ClampedGaussian, Vec3::Zero(), omega, r, eps), Vec3::Zero());
  // 2D: the same rotation sense for omega_z > 0.
  const Vec2 F2 = vortexParticleForce<2>(VortexKernel::Tent, Vec2(0.5, 0), VortexVector<2>(3.0), r, eps);
  EXPECT_NEAR(F2.x(), 0.0, 1e-15);
  EXPECT_GT(F2.y(), 0.0);
}
