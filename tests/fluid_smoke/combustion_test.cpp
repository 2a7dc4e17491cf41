// Stam's fire model (ch. 6.4.2-6.4.3) against its own closed forms and conservation laws.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/fluid/smoke/combustion.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

struct Fields {
  explicit Fields(const GridSpec<2>& spec) : fuel(spec), flame(spec), smoke(spec), T(spec, 293.15f) {}
  Grid<float, 2> fuel, flame, smoke, T;
  double total(const Grid<float, 2>& g) const {
    double s = 0.0;
    for (float v : g.data()) s += v;
    return s;
  }
};

}  // namespace

TEST(Combustion, ArrheniusRateIsEquationSixThree) {
  CombustionParams p;
  for (double T : {500.0, 1200.0, 2500.0})
    EXPECT_NEAR(flameCreationRate(p, 0.7, T), 0.28 * std::exp(-2300.0 / T) * 0.7, 1e-15);
  EXPECT_EQ(flameCreationRate(p, 0.0, 2000.0), 0.0);  // no fuel, no flame
  // The seed's "cold leakage" at 290 K: nu_a e^{-7.93} rho ~ 3.6e-4 nu_a rho.
  EXPECT_NEAR(flameCreationRate(p, 1.0, 290.0) / 0.28, 3.6e-4, 0.1e-4);
  p.ignitionTemperature = 600.0;  // the extension clamps it to zero below ignition
  EXPECT_EQ(flameCreationRate(p, 1.0, 590.0), 0.0);
  EXPECT_GT(flameCreationRate(p, 1.0, 610.0), 0.0);
}

TEST(Combustion, T4CoolingClosedFormMatchesRk4) {
  const double C = 2e-12, T0 = 1800.0, tEnd = 3.0;
  double T = T0;
  const int n = 3000;
  const double h = tEnd / n;
  auto f = [&](double x) { return -C * x * x * x * x; };
  for (int i = 0; i < n; ++i) {
    const double k1 = f(T), k2 = f(T + 0.5 * h * k1), k3 = f(T + 0.5 * h * k2), k4 = f(T + h * k3);
    T += h / 6 * (k1 + 2 * k2 + 2 * k3 + k4);
  }
  EXPECT_NEAR(radiativeCooling(T0, C, tEnd) / T, 1.0, 1e-8);
}

TEST(Combustion, MassMovesFuelToFlameToSmokeWithoutLoss) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(16, 16));
  Fields f(spec);
  for (std::size_t i = 0; i < f.fuel.count(); ++i) {
    f.fuel[i] = 0.5f + 0.5f * static_cast<float>(i % 7) / 7.0f;
    f.T[i] = 900.0f + 40.0f * static_cast<float>(i % 11);
  }
  CombustionParams p;
  const double before = f.total(f.fuel);
  double burnt = 0.0;
  for (int s = 0; s < 50; ++s) {
    const double fuelBefore = f.total(f.fuel), flameBefore = f.total(f.flame), smokeBefore = f.total(f.smoke);
    const CombustionTotals t = react<2>(p, 0.05, f.fuel, f.flame, f.smoke, f.T);
    EXPECT_NEAR(fuelBefore - f.total(f.fuel), t.fuelBurnt, 1e-4 * before);       // L_fuel = -S_flame
    EXPECT_NEAR(f.total(f.smoke) - smokeBefore, t.smokeCreated, 1e-4 * before);
    EXPECT_NEAR(f.total(f.flame) - flameBefore, t.fuelBurnt - t.smokeCreated, 1e-4 * before);
    burnt += t.fuelBurnt;
  }
  EXPECT_GT(burnt, 0.05 * before);  // it did burn
  EXPECT_NEAR(f.total(f.fuel) + f.total(f.flame) + f.total(f.smoke), before, 1e-5 * before);
}

TEST(Combustion, ReactionHeatsAndFiniteFuelBurnsOut) {
  const GridSpec<2> spec(Vec2::Zero(), 0.1, IVec2(1, 1));
  Fields f(spec);
  f.fuel[0] = 1.0f;
  f.T[0] = 1500.0f;
  CombustionParams p;
  p.ignitionTemperature = 500.0;
  const double T0 = f.T[0];
  const CombustionTotals first = react<2>(p, 0.01, f.fuel, f.flame, f.smoke, f.T);
  // Heat release of the first step, less at most a little radiation over 0.01 s.
  EXPECT_NEAR(f.T[0] - T0, p.heatRelease * first.fuelBurnt, 0.05 * p.heatRelease * first.fuelBurnt);
  float previousFuel = f.fuel[0];
  for (int s = 0; s < 4000; ++s) {
    react<2>(p, 0.01, f.fuel, f.flame, f.smoke, f.T);
    ASSERT_LE(f.fuel[0], previousFuel);
    previousFuel = f.fuel[0];
  }
  // Most fuel burnt; as the gas cools the Arrhenius rate falls, so a remnant smoulders slowly.
  EXPECT_LT(f.fuel[0], 0.05f);
  EXPECT_LT(f.flame[0], 0.005f);  // the flames went out into smoke
  EXPECT_GT(f.smoke[0], 0.94f);
  EXPECT_GE(f.T[0], static_cast<float>(p.ambientTemperature));
}

TEST(Combustion, RadiationScalesAsTemperatureToTheFourth) {
  // Doubling the temperature multiplies the initial cooling rate by 16 (seed: radiative symmetry).
  const double C = 1e-12, dt = 1e-6;
  const double slow = 1000.0 - radiativeCooling(1000.0, C, dt), fast = 2000.0 - radiativeCooling(2000.0, C, dt);
  EXPECT_NEAR(fast / slow, 16.0, 1e-3);
}
