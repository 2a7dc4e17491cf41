// Taylor-Green vortex u = sin x cos y, v = -cos x sin y on the box [0, pi]^2. The projection has
// walls, not periodic sides, and this mode needs none: its normal velocity vanishes on every side
// of the box and so does the shear du_t/dn (free slip). It is a steady solution of the Euler
// equations (pressure balances (u.grad)u), so without viscosity any energy loss is numerical. With
// viscosity, lap u = -2 u (k = 1 per axis), so u decays as exp(-2 nu t) and the kinetic energy as
//   E(t) = E0 exp(-4 nu t),   i.e.  nu_eff = -ln(E(t)/E0) / (4 t).
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "msim/fluid/smoke/smoke_solver.hpp"

using namespace msim;
using namespace msim::fluid;

namespace {

constexpr double kPi = std::numbers::pi;

struct Decay {
  double nuEff;    // -ln(E/E0) / (4 t)
  double maxDiv;   // after the last projection
};

Decay runTaylorGreen(int n, numerics::AdvectionScheme scheme, double nu, double endTime,
                     ViscosityMode mode = ViscosityMode::Implicit, double cfl = 1.0) {
  const GridSpec<2> spec(Vec2::Zero(), kPi / n, IVec2(n, n));
  SmokeParams<2> p;
  p.advection.scheme = scheme;
  p.viscosity = nu;
  p.viscosityMode = mode;
  p.wallSlip = WallSlip::FreeSlip;
  SmokeSolver<2> s(spec, p);
  for (int a = 0; a < 2; ++a) {
    auto& u = s.velocity().component(a);
    for (std::size_t i = 0; i < u.count(); ++i) {
      const Vec2 x = u.position(u.coord(i));
      u[i] = static_cast<float>(a == 0 ? std::sin(x.x()) * std::cos(x.y()) : -std::cos(x.x()) * std::sin(x.y()));
    }
  }
  const double e0 = s.statistics().kineticEnergy;
  const int steps = static_cast<int>(std::ceil(endTime / (cfl * spec.dx)));  // max speed is 1
  const double dt = endTime / steps;
  for (int k = 0; k < steps; ++k) s.step(dt);
  const auto st = s.statistics();
  return {-std::log(st.kineticEnergy / e0) / (4.0 * endTime), st.maxDivergence};
}

}  // namespace

TEST(TaylorGreen, MacCormackDissipatesLessThanSemiLagrangian) {
  for (int n : {32, 64}) {
    const Decay sl = runTaylorGreen(n, numerics::AdvectionScheme::FirstOrder, 0.0, 2.0);
    const Decay mc = runTaylorGreen(n, numerics::AdvectionScheme::MacCormack, 0.0, 2.0);
    std::printf("Taylor-Green n=%d CFL 1: nu_eff semi-Lagrangian %.3e, MacCormack %.3e\n", n, sl.nuEff, mc.nuEff);
    EXPECT_GT(sl.nuEff, 0.0);
    EXPECT_LT(mc.nuEff, 0.8 * sl.nuEff) << "n = " << n;
  }
  // At fixed CFL both shrink like dx: besides the interpolation error, the advect-then-project
  // splitting drops a dt^2/2 (u.grad)^2 u term each step, an O(dt) energy loss for any scheme.
  EXPECT_LT(runTaylorGreen(64, numerics::AdvectionScheme::FirstOrder, 0.0, 2.0).nuEff,
            0.7 * runTaylorGreen(32, numerics::AdvectionScheme::FirstOrder, 0.0, 2.0).nuEff);
}

TEST(TaylorGreen, ViscousDecayMatchesExpMinus4NuT) {
  // The measured rate is nu plus the numerical part above (about 1.5e-3 at n = 128, CFL 0.5).
  const double nu = 0.05;
  const Decay implicitRun = runTaylorGreen(128, numerics::AdvectionScheme::MacCormack, nu, 2.0, ViscosityMode::Implicit, 0.5);
  // Explicit diffusion is stable for nu dt / dx^2 <= 1/4: dt = 0.2 dx gives 0.16 at n = 64.
  const Decay explicitRun =
      runTaylorGreen(64, numerics::AdvectionScheme::MacCormack, nu, 2.0, ViscosityMode::Explicit, 0.2);
  std::printf("Taylor-Green nu=%.3f: measured nu implicit (n=128, CFL 0.5) %.5f, explicit (n=64, CFL 0.2) %.5f\n",
              nu, implicitRun.nuEff, explicitRun.nuEff);
  EXPECT_NEAR(implicitRun.nuEff, nu, 0.03 * nu);
  EXPECT_NEAR(explicitRun.nuEff, nu, 0.03 * nu);
  EXPECT_LT(implicitRun.maxDiv, 1e-3);
}
