// Conservation and analytic checks of the grid gas solver (Stam ch. 6.4.1 equations).
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>

#include "msim/fluid/gas/gas_solver.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

MotionField swirl(const Vec3& centre) {
  MotionFieldInstance v;
  v.type = MotionPrimitive::LineVortex;
  v.position = centre;
  v.magnitude = 0.6;
  v.coreRadius = 0.2;
  v.halfDistance = 0.25;
  return MotionField({v});
}

}  // namespace

TEST(GasSolver, ClosedBoxWithObstacleConservesMassOver100Steps) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 32, IVec3(32, 32, 32));
  GasSolver<3> gas(spec, GasParams{.densityDiffusion = 1e-4}, swirl(Vec3(0.5, 0.5, 0.5)),
                   numerics::TransportBoundaries<3>::allClosed());
  Grid<float, 3> solid(spec, 0.0f);
  for (std::size_t i = 0; i < solid.count(); ++i) {
    if ((solid.position(solid.coord(i)) - Vec3(0.5, 0.75, 0.5)).norm() < 0.1) solid[i] = 1.0f;
  }
  gas.setSolid(solid);
  auto& rho = gas.density();
  for (std::size_t i = 0; i < rho.count(); ++i)
    if (solid[i] < 0.5f && (rho.position(rho.coord(i)) - Vec3(0.3, 0.5, 0.5)).norm() < 0.15) rho[i] = 1.0f;
  const double before = gas.statistics().mass;
  const double dt = gas.stableTimestep();
  for (int s = 0; s < 100; ++s) gas.step(dt);
  const GasStatistics after = gas.statistics();
  RecordProperty("mass_ratio_minus_1", fmt::format("{:.4e}", after.mass / before - 1.0));
  EXPECT_NEAR(after.mass / before, 1.0, 1e-4);
  EXPECT_GT((after.centroid - Vec3(0.3, 0.5, 0.5)).norm(), 0.01);  // the gas did move
  for (std::size_t i = 0; i < rho.count(); ++i) {
    if (solid[i] > 0.5f) {
      ASSERT_EQ(rho[i], 0.0f);  // nothing leaks into the obstacle
    }
  }
}

TEST(GasSolver, PureDiffusionSpreadsAGaussianAtTwoKappaT) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 48, IVec3(48, 48, 48));
  const double kappa = 1e-3, sigma0 = 3.0 * spec.dx;
  GasSolver<3> gas(spec, GasParams{.densityDiffusion = kappa}, MotionField{},
                   numerics::TransportBoundaries<3>::allClosed());
  auto& rho = gas.density();
  const Vec3 c(0.5, 0.5, 0.5);
  for (std::size_t i = 0; i < rho.count(); ++i)
    rho[i] = static_cast<float>(std::exp(-(rho.position(rho.coord(i)) - c).squaredNorm() / (2 * sigma0 * sigma0)));
  auto variances = [&] {
    Vec3 m2 = Vec3::Zero();
    double m = 0.0;
    for (std::size_t i = 0; i < rho.count(); ++i) {
      const Vec3 d = rho.position(rho.coord(i)) - c;
      m += rho[i];
      m2 += rho[i] * d.cwiseProduct(d);
    }
    return Vec3(m2 / m);
  };
  const Vec3 v0 = variances();
  const double tEnd = 2.0 * sigma0 * sigma0 / (2 * kappa);
  const int steps = static_cast<int>(std::ceil(tEnd / gas.stableTimestep()));
  for (int s = 0; s < steps; ++s) gas.step(tEnd / steps);
  const Vec3 growth = (variances() - v0) / (2 * kappa * tEnd);
  RecordProperty("variance_growth_ratio", fmt::format("{:.4e}", growth.x()) + " " + fmt::format("{:.4e}", growth.y()) + " " +
                                              fmt::format("{:.4e}", growth.z()));
  for (int a = 0; a < 3; ++a) EXPECT_NEAR(growth[a], 1.0, 0.02) << "axis " << a;
}

TEST(GasSolver, SourceEmitsAtItsRateAndDissipationDecaysExponentially) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(20, 20));
  GasSolver<2> gas(spec, GasParams{}, MotionField{}, numerics::TransportBoundaries<2>::allClosed());
  GasSource source;
  source.densityRate = 2.0;
  source.temperature = 373.15;
  source.cells = {{gas.density().index(IVec2(10, 10)), 1.0f}, {gas.density().index(IVec2(11, 10)), 0.5f}};
  gas.addSource(source);
  for (int s = 0; s < 50; ++s) gas.step(0.02);
  const double expected = 2.0 * 1.5 * spec.cellVolume() * 1.0;  // rate * covered volume * time
  EXPECT_NEAR(gas.statistics().mass / expected, 1.0, 1e-5);
  EXPECT_NEAR(gas.statistics().meanTemperature, 373.15, 1e-3);  // pure emitted gas, mass-weighted

  GasSolver<2> fading(spec, GasParams{.densityDissipation = 0.7}, MotionField{},
                      numerics::TransportBoundaries<2>::allClosed());
  fading.density().fill(1.0f);
  const double m0 = fading.statistics().mass;
  for (int s = 0; s < 40; ++s) fading.step(0.05);
  EXPECT_NEAR(fading.statistics().mass / m0, std::exp(-0.7 * 2.0), 1e-5);
}

TEST(GasSolver, OpenBoundaryLetsGasLeave) {
  const GridSpec<2> spec(Vec2::Zero(), 0.05, IVec2(20, 20));
  MotionFieldInstance up;
  up.axis = Vec3::UnitY();
  GasSolver<2> gas(spec, GasParams{}, MotionField({up}), numerics::TransportBoundaries<2>::allOpen());
  gas.density().fill(1.0f);
  const double m0 = gas.statistics().mass;
  const double dt = gas.stableTimestep();
  for (double t = 0.0; t < 2.0; t += dt) gas.step(dt);  // twice the crossing time
  EXPECT_LT(gas.statistics().mass, 1e-3 * m0);
  EXPECT_TRUE(gas.statistics().finite);
}

namespace {

turbulence::TurbulentWind<2> breeze(double speedRms, const Vec2& mean, std::uint64_t seed = 3) {
  turbulence::SpectralWindParams w;
  w.resolution = 32;
  w.timeSamples = 8;
  w.period = 2.0;
  w.spectrum.largestEddy = 0.25;
  w.spectrum.smallestEddy = 2.0 / 32;
  w.spectrum.dissipation = w.spectrum.dissipationForSpeedRms(speedRms);
  w.seed = seed;
  return turbulence::TurbulentWind<2>(turbulence::SpectralWind<2>(w), Vec2::Zero(), mean);
}

// Second moment of the density about its centroid [m^2].
double spread(const GasSolver<2>& gas) {
  const GasStatistics s = gas.statistics();
  const auto& rho = gas.density();
  double m = 0.0, sum = 0.0;
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const Vec2 x = rho.position(rho.coord(i));
    m += rho[i];
    sum += rho[i] * (x - s.centroid.head<2>()).squaredNorm();
  }
  return sum / m;
}

}  // namespace

TEST(GasSolver, TurbulentWindIsAddedToTheMotionFieldAtTheCurrentTime) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / 32, IVec2(32, 32));
  MotionFieldInstance uniform;
  uniform.magnitude = 0.2;
  uniform.axis = Vec3::UnitX();
  GasSolver<2> gas(spec, GasParams{}, MotionField({uniform}), numerics::TransportBoundaries<2>::allOpen());
  const auto wind = breeze(0.1, Vec2(0.05, 0.0));
  gas.addWind(wind);
  gas.step(0.5 * gas.stableTimestep());
  gas.setTime(1.3);  // as a resumed run does
  for (int a = 0; a < 2; ++a) {
    const auto& u = gas.velocity().component(a);
    for (std::size_t i = 0; i < u.count(); i += 7) {
      const Vec2 x = u.position(u.coord(i));
      const double expected = (a == 0 ? 0.2 : 0.0) + wind.velocity(x, 1.3)[a];
      ASSERT_NEAR(u[i], expected, 1e-6) << a << " " << i;
    }
  }
}

TEST(GasSolver, TurbulentWindDispersesAPuffAndConservesMassInAClosedBox) {
  // Taylor dispersion: a puff spreads faster in turbulence than by molecular diffusion alone
  // (kappa = 2e-4 m^2/s: variance growth 2 D kappa t = 8e-4 m^2 in 1 s); the flux form keeps the mass in a closed box even though the sampled wind's discrete
  // divergence is not zero.
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / 96, IVec2(96, 96));
  auto puff = [&](GasSolver<2>& gas) {
    auto& rho = gas.density();
    for (std::size_t i = 0; i < rho.count(); ++i)
      rho[i] = static_cast<float>(std::exp(-(rho.position(rho.coord(i)) - Vec2(0.5, 0.5)).squaredNorm() / (2 * 0.03 * 0.03)));
  };
  const GasParams diffusive{.densityDiffusion = 2e-4};
  GasSolver<2> still(spec, diffusive, MotionField{}, numerics::TransportBoundaries<2>::allClosed());
  GasSolver<2> windy(spec, diffusive, MotionField{}, numerics::TransportBoundaries<2>::allClosed());
  windy.addWind(breeze(0.1, Vec2::Zero()));
  puff(still);
  puff(windy);
  const double before = windy.statistics().mass, spread0 = spread(windy);
  const double dt = std::min(windy.stableTimestep(), still.stableTimestep());
  for (double t = 0.0; t < 1.0 - 1e-9; t += dt) {
    still.step(dt);
    windy.step(dt);
  }
  const double grownStill = spread(still) - spread0, grownWindy = spread(windy) - spread0;
  std::printf("puff variance growth over 1 s: %.2e m^2 still, %.2e m^2 in the wind; mass change %.1e\n", grownStill,
              grownWindy, windy.statistics().mass / before - 1.0);
  EXPECT_NEAR(grownStill, 8e-4, 1e-4);
  EXPECT_GT(grownWindy, 3.0 * grownStill);
  EXPECT_NEAR(windy.statistics().mass / before, 1.0, 1e-5);
}
