// Enright's 3D deformation test (Enright, Fedkiw, Ferziger & Mitchell 2002, sec. 7.3; LeVeque's
// field): a sphere of radius 0.15 at (0.35, 0.35, 0.35) in the unit cube, stretched into a thin
// sheet by
//   u = 2 sin^2(pi x) sin(2 pi y) sin(2 pi z) c(t), v = -sin(2 pi x) sin^2(pi y) sin(2 pi z) c(t),
//   w = -sin(2 pi x) sin(2 pi y) sin^2(pi z) c(t),   c(t) = cos(pi t / T), T = 3,
// and brought back to the sphere at t = T. The volume after one period measures how much liquid a
// tracker loses where the sheet is thinner than the grid resolves.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "../sanitizer_build.hpp"
#include "msim/numerics/advection/advector.hpp"
#include "msim/numerics/level_set/fast_marching.hpp"
#include "msim/numerics/level_set/level_set_measures.hpp"
#include "msim/numerics/level_set/particle_level_set.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr double kPi = std::numbers::pi;
constexpr double kPeriod = 3.0;

// The field's spatial part on the faces (the time factor c(t) scales it each step).
MacGrid<3> spatialField(const GridSpec<3>& spec) {
  MacGrid<3> u(spec);
  for (int a = 0; a < 3; ++a) {
    auto& g = u.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec3 x = g.position(g.coord(i));
      const double s2x = std::sin(2 * kPi * x[0]), s2y = std::sin(2 * kPi * x[1]), s2z = std::sin(2 * kPi * x[2]);
      const double sx = std::sin(kPi * x[0]), sy = std::sin(kPi * x[1]), sz = std::sin(kPi * x[2]);
      g[i] = static_cast<float>(a == 0 ? 2.0 * sx * sx * s2y * s2z : a == 1 ? -s2x * sy * sy * s2z : -s2x * s2y * sz * sz);
    }
  }
  return u;
}

// Relative volume change after one period at n^3 cells.
double deform(int n, bool particles) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / n, IVec3::Constant(n));
  Grid<float, 3> phi(spec);
  for (std::size_t i = 0; i < phi.count(); ++i)
    phi[i] = static_cast<float>((phi.position(phi.coord(i)) - Vec3::Constant(0.35)).norm() - 0.15);
  const double initial = enclosedVolume(phi);
  const MacGrid<3> shape = spatialField(spec);
  MacGrid<3> u(spec);
  Advector<float, 3> advector(spec, AdvectionSettings{});
  ParticleLevelSet<3> pls(spec);
  if (particles) pls.seed(phi);
  const int steps = static_cast<int>(std::ceil(kPeriod / (spec.dx / 2.0)));  // CFL 1 for |u| <= 2
  const double dt = kPeriod / steps;
  for (int s = 0; s < steps; ++s) {
    const float c = static_cast<float>(std::cos(kPi * (s + 0.5) * dt / kPeriod));  // the step's midpoint
    for (int a = 0; a < 3; ++a)
      for (std::size_t i = 0; i < u.component(a).count(); ++i) u.component(a)[i] = c * shape.component(a)[i];
    advector.advect(phi, u, dt);
    if (particles) {
      pls.advect(u, dt);
      pls.correct(phi);
    }
    reinitializeFastMarching(phi, 5.0);
    if (particles) {
      pls.correct(phi);
      pls.adjustRadii(phi);
      if ((s + 1) % 20 == 0) pls.reseed(phi);
    }
  }
  return enclosedVolume(phi) / initial - 1.0;
}

}  // namespace

TEST(EnrightDeformation, ParticleLevelSetKeepsTheSphereVolume) {
  const int n = test::fullOrSanitized(100, 32);  // the 100^3 (Enright's finest grid)
  const double withParticles = deform(n, true), levelSetAlone = deform(n, false);
  RecordProperty("volume_change_pls", std::to_string(withParticles));
  RecordProperty("volume_change_level_set", std::to_string(levelSetAlone));
  EXPECT_LT(std::abs(withParticles), 0.03);
  EXPECT_LT(std::abs(withParticles), 0.1 * std::abs(levelSetAlone));
}
