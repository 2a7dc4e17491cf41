// The energy model of Narain ch. 3.4 against closed forms: decay without a mean flow, the steady
// level under steady shear, conservative diffusion, and the viscous cutoff that separates laminar
// from turbulent flow.
#include <gtest/gtest.h>

#include <cmath>

#include "msim/turbulence/turbulent_energy.hpp"

using namespace msim;
using namespace msim::turbulence;

namespace {

// u = (gamma (y - 1/2), 0, 0) on the faces of a unit box.
MacGrid<3> shear(const GridSpec<3>& spec, double gamma) {
  MacGrid<3> u(spec);
  auto& ux = u.component(0);
  for (std::size_t i = 0; i < ux.count(); ++i) ux[i] = static_cast<float>(gamma * (ux.position(ux.coord(i)).y() - 0.5));
  return u;
}

}  // namespace

TEST(TurbulentEnergy, DecaysAsTheCascadeDrainsItWithoutAMeanFlow) {
  // dE/dt = -k_0 E^(3/2): E(t) = (E(0)^(-1/2) + k_0 t / 2)^(-2).
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 16, IVec3(16, 16, 16));
  TurbulentEnergyParams p;
  p.largestEddy = 0.1;
  p.initialEnergy = 0.01;
  TurbulentEnergy<3> model(spec, p);
  const MacGrid<3> still(spec);
  double previous = p.initialEnergy;
  for (int s = 1; s <= 100; ++s) {
    model.step(still, 0.01);
    const double e = model.energy()(IVec3(8, 8, 8));
    ASSERT_LT(e, previous);
    previous = e;
  }
  const double exact = std::pow(std::pow(0.01, -0.5) + 10.0 * 1.0 / 2.0, -2.0);
  std::printf("E_0 after 1 s without mean flow: %.5f (exact %.5f)\n", previous, exact);
  EXPECT_NEAR(previous / exact, 1.0, 0.02);
}

TEST(TurbulentEnergy, SteadyShearReachesTheProductionCascadeBalance) {
  // G = Pi at E_0 = C S^2 l_0^2 (C the eddy viscosity constant, 0.09); simple shear gamma has
  // S^2 = gamma^2 / 2. Without diffusion: the
  // no-slip walls (ghost velocity 0 against +-1 m/s) produce far more energy next to them, which
  // the turbulent diffusion would carry into the middle (as the seed intends: boundary layers
  // generate turbulence, ch. 3.4.2).
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 32, IVec3(32, 32, 8));
  TurbulentEnergyParams p;
  p.largestEddy = 0.1;
  p.diffusion = false;
  TurbulentEnergy<3> model(spec, p);
  const double gamma = 2.0;
  const MacGrid<3> u = shear(spec, gamma);
  for (int s = 0; s < 800; ++s) model.step(u, 0.05);  // relaxes at k_0 sqrt(E_0) = 0.42 /s near the balance
  const double balance = p.eddyViscosityConstant * gamma * gamma / 2.0 * 0.1 * 0.1;
  const double centre = model.energy()(IVec3(16, 16, 4));
  std::printf("steady shear: E_0 = %.6f, balance C S^2 l_0^2 = %.6f, S^2 = %.4f (gamma^2/2 = 2)\n", centre, balance,
              double(model.strain2()(IVec3(16, 16, 4))));
  EXPECT_NEAR(model.strain2()(IVec3(16, 16, 4)), 2.0, 1e-4);
  EXPECT_NEAR(centre / balance, 1.0, 0.01);
  // And it stays there.
  for (int s = 0; s < 50; ++s) model.step(u, 0.05);
  EXPECT_NEAR(model.energy()(IVec3(16, 16, 4)) / balance, 1.0, 0.01);
}

TEST(TurbulentEnergy, ReactionIsStableForLargeSteps) {
  // Backward Euler above the balance, forward Euler below it, never past it, for any dt.
  const double k0 = 10.0, s2 = 2.0, balance = s2 / (k0 * k0);
  for (const double dt : {1e-3, 0.1, 10.0, 1e4}) {
    const double fromAbove = TurbulentEnergy<3>::react(100.0 * balance, s2, k0, dt);
    const double fromBelow = TurbulentEnergy<3>::react(1e-4 * balance, s2, k0, dt);
    EXPECT_GE(fromAbove, balance * (1 - 1e-12)) << dt;
    EXPECT_LT(fromAbove, 100.0 * balance) << dt;
    EXPECT_LE(fromBelow, balance * (1 + 1e-12)) << dt;
    EXPECT_GT(fromBelow, 1e-4 * balance) << dt;
  }
  EXPECT_NEAR(TurbulentEnergy<3>::react(100.0 * balance, s2, k0, 1e6), balance, 1e-3 * balance);
  EXPECT_EQ(TurbulentEnergy<3>::react(0.0, s2, k0, 1.0), 0.0);
}

TEST(TurbulentEnergy, DiffusionSpreadsEnergyAndConservesIt) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / 64, IVec2(64, 64));
  TurbulentEnergyParams p;
  p.largestEddy = 0.1;
  TurbulentEnergy<2> model(spec, p);
  Grid<float, 2> solid(spec, 0.0f);
  for (int j = 20; j < 44; ++j) solid(IVec2(40, j)) = 1.0f;  // a wall segment
  model.setSolid(solid);
  auto& e = model.energy();
  for (std::size_t i = 0; i < e.count(); ++i) {
    if (solid[i] > 0.5f) continue;
    e[i] = static_cast<float>(0.01 * std::exp(-(e.position(e.coord(i)) - Vec2(0.4, 0.5)).squaredNorm() / (2 * 0.05 * 0.05)));
  }
  const double before = model.integral(), peak = e(IVec2(25, 32));
  for (int s = 0; s < 20; ++s) model.diffuse(0.05);
  std::printf("diffusion: integral %.6e -> %.6e, peak %.5f -> %.5f\n", before, model.integral(), peak,
              double(e(IVec2(25, 32))));
  EXPECT_NEAR(model.integral() / before, 1.0, 1e-5);
  EXPECT_LT(e(IVec2(25, 32)), 0.9 * peak);
  for (int j = 20; j < 44; ++j) EXPECT_EQ(e(IVec2(40, j)), 0.0f);
}

TEST(TurbulentEnergy, ViscousCutoffSwitchesTurbulenceOnAsShearRises) {
  // Eq. 3.9-3.10: at the shear balance E_0 = C S^2 l_0^2, so k_nu = (k_0 E_0^(3/2) / nu^3)^(1/4) rises
  // with the shear; the octaves carry energy only below k_nu. Three shear rates, nu of air.
  const GridSpec<3> spec(Vec3::Zero(), 0.025, IVec3(8, 8, 8));
  TurbulentEnergyParams p;  // l_0 = 4 cells = 0.1 m, nu = 1.5e-5
  TurbulentEnergy<3> model(spec, p);
  double previous = -1.0;
  for (const double gamma : {0.002, 0.02, 2.0}) {
    const double e0 = p.eddyViscosityConstant * gamma * gamma / 2.0 * 0.01;
    double synthesised = 0.0;
    for (int i = 0; i < 5; ++i) synthesised += model.octaveEnergy(e0, i);
    std::printf("shear %.3f 1/s: E_0 = %.3e, k_nu / k_0 = %.2f, five octaves hold %.3e m^2/s^2\n", gamma, e0,
                model.viscousCutoff(e0) / model.k0(), synthesised);
    EXPECT_GE(synthesised, previous);
    previous = synthesised;
    if (gamma == 0.002) {
      EXPECT_EQ(synthesised, 0.0);  // laminar: k_nu below k_0
    }
  }
  EXPECT_GT(previous, 0.0);
  // Without the cutoff the octaves follow E_i = E_0 2^(-2i/3) (eq. 3.4).
  TurbulentEnergyParams inviscid;
  inviscid.viscosity = 0.0;
  const TurbulentEnergy<3> free(spec, inviscid);
  for (int i = 0; i < 5; ++i) EXPECT_NEAR(free.octaveEnergy(1.0, i), std::pow(2.0, -2.0 * i / 3.0), 1e-12);
  // A partial octave keeps the part below the cutoff: k_nu = 1.5 k_i keeps half.
  const double k1 = 2.0 * free.k0();
  const double energyForCutoff = std::pow(std::pow(1.5 * k1, 4) * std::pow(p.viscosity, 3) / model.k0(), 2.0 / 3.0);
  EXPECT_NEAR(model.octaveEnergy(energyForCutoff, 1) / (energyForCutoff * std::pow(2.0, -2.0 / 3.0)), 0.5, 1e-9);
}
