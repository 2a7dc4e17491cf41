// Noise particles (Narain ch. 3.5.1): the synthesised u' is divergence-free, carries the energy of
// the octaves, vanishes where the model has none, and the particles move with the mean flow and
// keep covering the fluid.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/turbulence/noise_particles.hpp"

using namespace msim;
using namespace msim::turbulence;

namespace {

TurbulentEnergyParams inviscid() {
  TurbulentEnergyParams p;
  p.viscosity = 0.0;  // no cutoff: every octave carries E_0 2^(-2i/3)
  return p;
}

}  // namespace

TEST(NoiseParticles, SynthesisedVelocityIsIncompressibleAndCarriesTheOctavesEnergy) {
  const GridSpec<3> coarse(Vec3::Zero(), 1.0 / 16, IVec3(16, 16, 16));  // l_0 = 4 cells = 0.25 m
  const GridSpec<3> fine(Vec3::Zero(), 1.0 / 64, IVec3(64, 64, 64));
  TurbulentEnergy<3> energy(coarse, inviscid());
  energy.energy().fill(0.01f);
  NoiseParticles<3> particles(coarse, energy, fine.dx, NoiseParticleParams{.seed = 2});
  EXPECT_EQ(particles.octaves(), 3);  // l_i = 0.25, 0.125, 0.0625 m: l_i / 2 spans >= 2 fine cells
  EXPECT_EQ(particles.size(), 64u);   // one per cell of side l_0
  MacGrid<3> u(fine);
  particles.synthesize(energy, u);
  double worstDiv = 0.0, largest = 0.0, sum2 = 0.0;
  int counted = 0;
  for (int k = 0; k < 64; ++k)
    for (int j = 0; j < 64; ++j)
      for (int i = 0; i < 64; ++i) {
        const IVec3 c(i, j, k);
        double div = 0.0;
        Vec3 centre;
        for (int a = 0; a < 3; ++a) {
          IVec3 up = c;
          up[a] += 1;
          div += u.component(a)(up) - u.component(a)(c);
          centre[a] = 0.5 * (u.component(a)(up) + u.component(a)(c));
          largest = std::max(largest, double(std::abs(u.component(a)(c))));
        }
        worstDiv = std::max(worstDiv, std::abs(div));
        if (c.minCoeff() >= 8 && c.maxCoeff() < 56) {
          sum2 += centre.squaredNorm();
          ++counted;
        }
      }
  double octaves = 0.0;
  for (int i = 0; i < 3; ++i) octaves += 0.01 * std::pow(2.0, -2.0 * i / 3.0);
  // Each particle's noise has <|u|^2> = sum E_i; eq. 3.12 averages independent noises with the
  // weights w_j = rho_j / sum rho, which scales the variance by sum w_j^2: the prediction is that
  // factor, averaged over the same cells, times sum E_i (the weights' own gradients add a little).
  double blend = 0.0;
  for (int k = 8; k < 56; ++k)
    for (int j = 8; j < 56; ++j)
      for (int i = 8; i < 56; ++i) {
        const Vec3 x = (Vec3(i, j, k) + Vec3::Constant(0.5)) * fine.dx;
        double sum = 0.0, sumSquares = 0.0;
        for (const Vec3& p : particles.positions()) {
          const double q = std::min(1.0, (x - p).norm() / 0.25);
          const double rho = 1.0 - 3.0 * q * q + 2.0 * q * q * q;
          sum += rho;
          sumSquares += rho * rho;
        }
        if (sum > 0.0) blend += sumSquares / (sum * sum) / counted;  // no particle within l_0: no noise
      }
  std::printf("u': max |div| dx / max |u'| = %.1e; interior <|u'|^2> = %.5f against sum E_i = %.4f times the blend's "
              "variance factor %.3f = %.5f\n",
              worstDiv / largest, sum2 / counted, octaves, blend, octaves * blend);
  EXPECT_LT(worstDiv, 1e-5 * largest);
  EXPECT_NEAR(sum2 / counted / (octaves * blend), 1.0, 0.15);

  // The intensity scales u' and nothing else: the same particles at half the intensity.
  NoiseParticles<3> half(coarse, energy, fine.dx, NoiseParticleParams{.seed = 2, .intensity = 0.5});
  MacGrid<3> uHalf(fine);
  half.synthesize(energy, uHalf);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < u.component(a).count(); ++i)
      ASSERT_NEAR(uHalf.component(a)[i], 0.5f * u.component(a)[i], 1e-6f * largest);

  // No energy, no turbulence.
  energy.energy().fill(0.0f);
  particles.synthesize(energy, u);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < u.component(a).count(); ++i) ASSERT_EQ(u.component(a)[i], 0.0f);
}

TEST(NoiseParticles, MoveWithTheMeanFlowAndKeepCoveringTheFluid) {
  const GridSpec<2> coarse(Vec2::Zero(), 1.0 / 32, IVec2(32, 32));  // l_0 = 0.125 m: 8 x 8 cells
  TurbulentEnergy<2> energy(coarse, inviscid());
  Grid<float, 2> solid(coarse, 0.0f);
  for (int j = 0; j < 32; ++j)
    for (int i = 12; i < 20; ++i)
      if (j >= 12 && j < 20) solid(IVec2(i, j)) = 1.0f;  // a block in the middle
  energy.setSolid(solid);
  NoiseParticles<2> particles(coarse, energy, coarse.dx / 4, NoiseParticleParams{.seed = 5}, &solid);
  const std::size_t initial = particles.size();
  EXPECT_EQ(initial, 60u);  // 64 cells, the 2 x 2 under the block hold no fluid
  MacGrid<2> wind(coarse);
  wind.component(0).fill(0.3f);  // blows out through x = 1
  const std::vector<Vec2> before = particles.positions();
  particles.advance(wind, energy, 0.1);
  // The survivors moved 3 cm along x (they keep their order within their cells).
  int moved = 0;
  for (const Vec2& p : particles.positions())
    for (const Vec2& q : before)
      if ((p - q - Vec2(0.03, 0.0)).norm() < 1e-6) ++moved;
  EXPECT_GT(moved, 40);
  for (int s = 0; s < 50; ++s) particles.advance(wind, energy, 0.1);
  // Five seconds later everything has left through x = 1; every fluid cell of side l_0 has a particle.
  std::vector<int> count(64, 0);
  for (const Vec2& p : particles.positions()) {
    ASSERT_GE(p.x(), 0.0);
    ASSERT_LT(p.x(), 1.0);
    const IVec2 c(static_cast<int>(p.x() * 32), static_cast<int>(p.y() * 32));
    ASSERT_LE(solid(c), 0.5f);
    ++count[static_cast<int>(p.x() / 0.125) + 8 * static_cast<int>(p.y() / 0.125)];
  }
  int empty = 0;
  for (int c = 0; c < 64; ++c) empty += count[c] == 0;
  EXPECT_LE(empty, 4);  // at most the cells the block fills
  EXPECT_LE(particles.size(), 3 * 64u);
}
