// A turbulent wind acting on smoke as a drag force, du/dt = c (u_wind - u) (smoke.wind_coupling).
#include <gtest/gtest.h>

#include <cmath>

#include "msim/fluid/smoke/smoke_solver.hpp"

using namespace msim;
using namespace msim::fluid;

TEST(SmokeWind, AirAtRestRelaxesTowardsTheWindAtTheCouplingRate) {
  // A frozen wind (one time sample) on air at rest: without the walls and the self-advection the
  // faces would reach (1 - exp(-c t)) u_wind. Far from the walls, regress u on u_wind.
  const int n = 64;
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / n, IVec2(n, n));
  SmokeParams<2> params;
  params.windCoupling = 2.0;
  SmokeSolver<2> smoke(spec, params);
  turbulence::SpectralWindParams w;
  w.resolution = 32;
  w.timeSamples = 1;
  w.spectrum.largestEddy = 0.25;
  w.spectrum.smallestEddy = 2.0 / 32;
  w.spectrum.dissipation = w.spectrum.dissipationForSpeedRms(0.05);
  turbulence::TurbulentWind<2> wind(turbulence::SpectralWind<2>(w), Vec2::Zero(), Vec2::Zero());
  smoke.addWind(wind);
  EXPECT_NEAR(smoke.maxWindSpeed(), wind.maxSpeed(), 1e-12);
  const double dt = 0.01;
  for (int s = 0; s < 50; ++s) smoke.step(dt);
  EXPECT_NEAR(smoke.time(), 0.5, 1e-12);
  double uw = 0.0, ww = 0.0, uu = 0.0;
  for (int a = 0; a < 2; ++a) {
    const auto& u = smoke.velocity().component(a);
    for (std::size_t i = 0; i < u.count(); ++i) {
      const IVec2 f = u.coord(i);
      if (f.minCoeff() < 8 || f.maxCoeff() > n - 8) continue;
      const double target = wind.velocity(u.position(f), 0.0)[a];
      uw += u[i] * target;
      ww += target * target;
      uu += double(u[i]) * u[i];
    }
  }
  const double slope = uw / ww, correlation = uw / std::sqrt(uu * ww);
  const double expected = 1.0 - std::exp(-2.0 * 0.5);
  std::printf("u ~ %.3f u_wind (exact relaxation: %.3f), correlation %.3f\n", slope, expected, correlation);
  EXPECT_NEAR(slope, expected, 0.08);
  EXPECT_GT(correlation, 0.95);
}
