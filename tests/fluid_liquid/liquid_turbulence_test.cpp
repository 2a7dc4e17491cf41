// Sub-grid turbulence at a free surface (Narain 2011 ch. 3.5.3, issue #24): the fine surface's
// detail relaxes towards the simulation's surface over tau' = dx / sqrt(g dx / (2 pi)) (eq. 3.13),
// the ripples carry the energy E' = (delta / tau')^2 (eq. 3.14), eddies touch only the surface,
// ripples die out once the flow that made them stops, and the fine surface follows the simulated
// liquid's.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include "../cell_field.hpp"
#include "msim/core/interpolation.hpp"
#include "msim/fluid/liquid/liquid_solver.hpp"
#include "msim/fluid/liquid/liquid_turbulence.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

constexpr double kSurface = 0.5;  // the flat surface's height [m]

// A unit 2D box of n simulation cells per axis with a flat surface at kSurface.
struct FlatTank {
  explicit FlatTank(int n, LiquidTurbulenceParams params = quietParams())
      : spec(Vec<2>::Zero(), 1.0 / n, IVec<2>::Constant(n)),
        coarsePhi(test::cellField<2>(spec, [](const Vec<2>& x) { return x[1] - kSurface; })),
        velocity(spec),
        turbulence(spec, params, numerics::AdvectionSettings{}, coarsePhi, nullptr) {}

  // No eddies: the noise has no amplitude, so only eq. 3.13 acts on the detail.
  static LiquidTurbulenceParams quietParams() {
    LiquidTurbulenceParams p;
    p.particles.intensity = 0.0;
    p.energy.initialEnergy = 0.0;
    return p;
  }

  // The fine surface rippled: phi = phi~ - a sin(2 pi x / wavelength).
  void ripple(double amplitude, double wavelength) {
    Grid<float, 2> phi = turbulence.phi();
    for (std::size_t i = 0; i < phi.count(); ++i) {
      const Vec<2> x = phi.position(phi.coord(i));
      phi[i] -= static_cast<float>(amplitude * std::sin(2.0 * std::numbers::pi * x[0] / wavelength));
    }
    turbulence.restoreSurface(phi, coarsePhi);
  }

  GridSpec<2> spec;
  Grid<float, 2> coarsePhi;
  MacGrid<2> velocity;
  LiquidTurbulence<2> turbulence;
};

TEST(LiquidTurbulence, RelaxationTimeIsTheGravityWavePeriodOfACell) {
  // dx = 0.1 m, g = 9.81: c = sqrt(0.981 / 6.2832) = 0.39514 m/s, tau' = 0.1 / c = 0.25308 s.
  const FlatTank tank(10);
  EXPECT_NEAR(tank.turbulence.relaxationTime(), 0.25308, 1e-4);
}

TEST(LiquidTurbulence, RipplesRelaxTowardsTheSimulatedSurfaceAsEquation313) {
  // Without eddies or flow eq. 3.13 alone acts: the detail shrinks by (1 - dt / tau') per step,
  // and delta, the mean |phi - phi~| near the surface, with it. The ripple has a wavelength of two
  // simulation cells, so each cell's four fine columns sample |sin| at pi/8 and 3pi/8 twice.
  FlatTank tank(16);
  const double dx = tank.spec.dx, amplitude = 0.25 * dx;
  tank.ripple(amplitude, 2.0 * dx);
  const double dt = 0.01, tau = tank.turbulence.relaxationTime();
  const double sampledMean = 0.5 * (std::sin(std::numbers::pi / 8) + std::sin(3 * std::numbers::pi / 8));
  for (int step = 1; step <= 20; ++step) {
    tank.turbulence.step(tank.velocity, tank.coarsePhi, dt);
    const double expected = amplitude * sampledMean * std::pow(1.0 - dt / tau, step);
    ASSERT_NEAR(tank.turbulence.meanRippleHeight(), expected, 0.02 * expected) << "step " << step;
  }
  // E' = (delta / tau')^2 in the cells at the surface (eq. 3.14).
  const double delta = tank.turbulence.meanRippleHeight();
  const IVec<2> surfaceCell(8, static_cast<int>(kSurface / dx));
  EXPECT_NEAR(tank.turbulence.rippleEnergy()(surfaceCell), std::pow(delta / tau, 2), 0.02 * std::pow(delta / tau, 2));
  // Deep in the liquid there are no ripples to carry energy.
  EXPECT_EQ(tank.turbulence.rippleEnergy()(IVec<2>(8, 1)), 0.0f);
}

TEST(LiquidTurbulence, EddiesRippleOnlyTheSurfaceAndDieOutWithoutTheFlow) {
  // Turbulent energy in a still tank: the eddies ripple the fine surface and leave phi = phi~ deep
  // in the liquid and high in the air. Once the energy of the flow is gone, the ripples' own
  // energy E' (eq. 3.14) moves them but cannot hold them up against eq. 3.13 (the noise's eddies
  // are slower than sqrt(E'), noise_particles.hpp): they die out.
  LiquidTurbulenceParams params;
  params.energy.initialEnergy = 0.0;
  FlatTank tank(32, params);
  tank.turbulence.energy().energy().fill(0.02f);  // eddies of ~0.14 m/s
  const double dt = 0.01, tau = tank.turbulence.relaxationTime();
  double peak = 0.0;
  for (int step = 0; step < 10; ++step) {
    tank.turbulence.step(tank.velocity, tank.coarsePhi, dt);
    peak = std::max(peak, tank.turbulence.meanRippleHeight());
  }
  EXPECT_GT(peak, 0.02 * tank.spec.dx) << "the eddies should ripple the surface";
  const Grid<float, 2>& phi = tank.turbulence.phi();
  double deepest = 0.0;
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const double smooth = sampleLinear<2>(tank.coarsePhi, phi.position(phi.coord(i)));
    if (std::abs(smooth) > 12.0 * tank.spec.dx) deepest = std::max(deepest, std::abs(phi[i] - smooth));
  }
  EXPECT_LT(deepest, 1e-6) << "eddies reached cells far from the surface";
  tank.turbulence.energy().energy().fill(0.0f);
  const int decaySteps = static_cast<int>(std::ceil(20.0 * tau / dt));
  for (int step = 0; step < decaySteps; ++step) tank.turbulence.step(tank.velocity, tank.coarsePhi, dt);
  // Measured: half the peak after 4 tau' (the noise's eddies keep their direction for a while),
  // then an e-fold per 6 tau'; 5% of the peak after 20 tau'.
  EXPECT_LT(tank.turbulence.meanRippleHeight(), 0.1 * peak) << "after 20 tau' the ripples should have died out";
}

TEST(LiquidTurbulence, FineSurfaceFollowsTheSimulatedLiquid) {
  // A 2D dam break with eddies: the fine surface, carried by U + u' and tied to the particle level
  // set's surface by eq. 3.13, holds the simulated liquid's volume (the eddies are divergence-free)
  // and its zero crossing stays within a simulation cell of the simulated one.
  const int n = 48;
  const GridSpec<2> spec(Vec<2>::Zero(), 1.0 / n, IVec<2>::Constant(n));
  LiquidSolver<2> solver(spec, LiquidParams<2>{});
  solver.addLiquid(test::cellField<2>(spec, [](const Vec<2>& x) { return std::max(x[0] - 0.3, x[1] - 0.5); }));
  LiquidTurbulenceParams params;
  params.energy.initialEnergy = 0.01;
  LiquidTurbulence<2> turbulence(spec, params, solver.params().advection, solver.phi(), nullptr);
  double ripple = 0.0;
  for (int frame = 0; frame < 30; ++frame) {
    solver.advance(1.0 / 60.0);
    turbulence.step(solver.velocity(), solver.phi(), 1.0 / 60.0);
    ripple = std::max(ripple, turbulence.meanRippleHeight());
  }
  EXPECT_GT(ripple, 0.01 * spec.dx);
  const double coarse = numerics::enclosedVolume(solver.phi()), fine = numerics::enclosedVolume(turbulence.phi());
  EXPECT_NEAR(fine / coarse, 1.0, 0.02);
  const Grid<float, 2>& phi = turbulence.phi();
  for (std::size_t i = 0; i < phi.count(); ++i) {
    const Vec<2> x = phi.position(phi.coord(i));
    ASSERT_LE(std::abs(phi[i] - sampleLinear<2>(solver.phi(), x)), spec.dx + 1e-6) << "fine cell " << i;
  }
}

}  // namespace
