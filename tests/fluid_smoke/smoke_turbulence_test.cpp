// The coupling pieces of procedural turbulence in smoke (Narain ch. 3.5.2): u' averaged onto the
// simulation faces stays divergence-free, the coarse scalars are the fine ones averaged, and the
// fine smoke follows U + u'.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/fluid/smoke/smoke_turbulence.hpp"

using namespace msim;
using namespace msim::fluid;

TEST(SmokeTurbulence, CoarseTurbulenceIsDivergenceFreeAndScalarsAverage) {
  const GridSpec<3> coarse(Vec3::Zero(), 1.0 / 16, IVec3(16, 16, 16));
  SmokeTurbulenceParams params;
  params.energy.viscosity = 0.0;
  params.energy.initialEnergy = 0.02;
  SmokeTurbulence<3> turbulence(coarse, params, numerics::AdvectionSettings{}, nullptr, 293.15);
  SmokeSource<3> source;
  for (std::size_t i = 0; i < turbulence.density().count(); ++i)
    if ((turbulence.density().position(turbulence.density().coord(i)) - Vec3(0.5, 0.5, 0.5)).norm() < 0.2)
      source.cells.emplace_back(i, 1.0f);
  source.density = 1.0;
  turbulence.addSource(source);
  // A slow swirl as the simulated flow.
  MacGrid<3> u(coarse);
  for (int a = 0; a < 2; ++a) {
    auto& g = u.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec3 x = g.position(g.coord(i)) - Vec3(0.5, 0.5, 0.5);
      g[i] = static_cast<float>(a == 0 ? -0.3 * x.y() : 0.3 * x.x());
    }
  }
  Grid<float, 3> rho(coarse, 0.0f), temperature(coarse, 293.15f);
  rho.fill(1.0f);  // smoke everywhere: u' is synthesised over the whole grid
  for (int s = 0; s < 3; ++s) {
    turbulence.applySources(0.02, rho, temperature);
    turbulence.step(u, 0.02, rho, temperature);
  }
  const auto& ut = turbulence.coarseTurbulentVelocity();
  double worst = 0.0, largest = 0.0;
  for (int k = 0; k < 16; ++k)
    for (int j = 0; j < 16; ++j)
      for (int i = 0; i < 16; ++i) {
        const IVec3 c(i, j, k);
        double div = 0.0;
        for (int a = 0; a < 3; ++a) {
          IVec3 up = c;
          up[a] += 1;
          div += ut.component(a)(up) - ut.component(a)(c);
          largest = std::max(largest, double(std::abs(ut.component(a)(c))));
        }
        worst = std::max(worst, std::abs(div));
      }
  std::printf("coarse u': max |div| dx / max |u'| = %.1e (max |u'| %.3f m/s), band %.2f\n", worst / largest, largest,
              turbulence.bandFraction());
  EXPECT_GT(largest, 0.01);
  EXPECT_LT(worst, 1e-5 * largest);
  // The coarse density is the mean of its 64 fine cells.
  double fine = 0.0;
  for (int k = 0; k < 4; ++k)
    for (int j = 0; j < 4; ++j)
      for (int i = 0; i < 4; ++i) fine += turbulence.density()(IVec3(32 + i, 32 + j, 32 + k));
  EXPECT_NEAR(rho(IVec3(8, 8, 8)), fine / 64, 1e-6);
  EXPECT_GT(rho(IVec3(8, 8, 8)), 0.5);
  EXPECT_GT(turbulence.turbulentKineticEnergy(), 0.0);
}

TEST(SmokeTurbulence, FineSmokeDissipatesAtTheSmokeRates) {
  // The fine grid carries the smoke, so the smoke's decay rates act there: in still air with no
  // energy, the fine mass falls as exp(-rate t) and T - T_ambient likewise.
  const GridSpec<2> coarse(Vec2::Zero(), 1.0 / 16, IVec2(16, 16));
  SmokeTurbulenceParams params;
  params.energy.initialEnergy = 0.0;
  params.densityDissipation = 2.0;
  params.temperatureDissipation = 1.0;
  SmokeTurbulence<2> turbulence(coarse, params, numerics::AdvectionSettings{}, nullptr, 293.15);
  for (int j = 24; j < 40; ++j)
    for (int i = 24; i < 40; ++i) {
      turbulence.density()(IVec2(i, j)) = 1.0f;
      turbulence.temperature()(IVec2(i, j)) = 393.15f;
    }
  const MacGrid<2> still(coarse);
  Grid<float, 2> rho(coarse, 0.0f), temperature(coarse, 293.15f);
  for (int s = 0; s < 10; ++s) turbulence.step(still, 0.05, rho, temperature);
  double mass = 0.0;
  for (std::size_t i = 0; i < turbulence.density().count(); ++i) mass += turbulence.density()[i];
  EXPECT_NEAR(mass / 256.0, std::exp(-1.0), 1e-4);
  EXPECT_NEAR(turbulence.temperature()(IVec2(32, 32)) - 293.15, 100.0 * std::exp(-0.5), 1e-2);
  EXPECT_NEAR(rho(IVec2(8, 8)), std::exp(-1.0), 1e-4);  // the coarse average follows
}
