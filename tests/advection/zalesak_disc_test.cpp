// Selle ch. 2.8, Figures 2.6-2.8: Zalesak's slotted disc (centre (50,75), radius 15, slot 5 x 25
// cut up from the bottom of the disc) as a signed distance on [0,100]^2, rotated once
// (t = 628) by V = pi/314 (50 - y, x - 50). "Grid size 101^2" means 101 nodes per axis (dx = 1);
// "Error" is the average |phi - phi_0| over all nodes of [0,100]^2.
//
// The computational grid extends 21 cells beyond [0,100]^2 on every side so the circle through
// the corners (radius 50 sqrt 2) lies inside it: the measured nodes then only ever see data that
// started inside the grid, which stands in for the exact inflow data the tables imply (with
// zero-gradient inflow at x = 0 or 100 the errors are 10x larger than Selle's). The dt is
// CFL dx / max(|u| + |v|) over [0,100]^2. Only 101^2 runs here (finer grids take minutes); the
// finer rows and the entries this setup does not reproduce are in docs/advection.md.
#include <fmt/format.h>
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

constexpr double kOmega = std::numbers::pi / 314.0;
constexpr int kNodes = 101;
constexpr int kPad = 21;

double boxDistance(const Vec2& p, const Vec2& centre, const Vec2& half) {
  const Vec2 d = (p - centre).cwiseAbs() - half;
  return d.cwiseMax(0.0).norm() + std::min(std::max(d.x(), d.y()), 0.0);
}

// Disc minus slot, as the usual CSG combination of the two exact distances.
double slottedDisc(const Vec2& p) {
  const double disc = (p - Vec2(50, 75)).norm() - 15.0;
  const double slot = boxDistance(p, Vec2(50, 72.5), Vec2(2.5, 12.5));
  return std::max(disc, -slot);
}

double averageError(BuildingBlock block, AdvectionScheme scheme, double cfl) {
  const double dx = 100.0 / (kNodes - 1);
  const GridSpec<2> spec(Vec2::Constant(-(kPad + 0.5) * dx), dx, IVec2::Constant(kNodes + 2 * kPad));
  MacGrid<2> velocity(spec);
  for (int a = 0; a < 2; ++a) {
    auto& g = velocity.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec2 p = g.position(g.coord(i));
      g[i] = static_cast<float>(a == 0 ? kOmega * (50.0 - p.y()) : kOmega * (p.x() - 50.0));
    }
  }
  AdvectionSettings settings;
  settings.block = block;
  settings.scheme = scheme;
  settings.limiter = ExtremaLimiter::None;
  settings.trace = BackTrace::RK2;
  Advector<double, 2> advector(spec, settings);
  Grid<double, 2> phi(spec), phi0(spec);
  for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = phi0[i] = slottedDisc(phi.position(phi.coord(i)));
  const double dt = cfl * dx / (kOmega * 100.0), end = 2.0 * std::numbers::pi / kOmega;  // = 628
  for (double t = 0.0; t < end - 1e-9;) {
    const double step = std::min(dt, end - t);
    advector.advect(phi, velocity, step);
    t += step;
  }
  double sum = 0.0;
  for (int j = 0; j < kNodes; ++j)
    for (int i = 0; i < kNodes; ++i) {
      const IVec2 c(i + kPad, j + kPad);
      sum += std::abs(phi(c) - phi0(c));
    }
  return sum / (kNodes * kNodes);
}

void expectWithin15Percent(const char* name, BuildingBlock block, AdvectionScheme scheme, double cfl, double selle) {
  const double e = averageError(block, scheme, cfl);
  std::cout << fmt::format("{:28s} 101^2 error {:.3e} (Selle {:.1e})\n", name, e, selle);
  EXPECT_NEAR(e, selle, 0.15 * selle) << name;
}

}  // namespace

TEST(ZalesakDisc, Figure2_6_UpwindBuildingBlocksCfl075) {
  expectWithin15Percent("BFECC (upwind)", BuildingBlock::Upwind, AdvectionScheme::BFECC, 0.75, 8.9e-2);
  expectWithin15Percent("MacCormack (upwind)", BuildingBlock::Upwind, AdvectionScheme::MacCormack, 0.75, 1.6e-1);
}

TEST(ZalesakDisc, Figure2_7_SemiLagrangianBuildingBlocksCfl075) {
  expectWithin15Percent("semi-Lagrangian", BuildingBlock::SemiLagrangian, AdvectionScheme::FirstOrder, 0.75, 1.8);
  expectWithin15Percent("BFECC (semi-Lagrangian)", BuildingBlock::SemiLagrangian, AdvectionScheme::BFECC, 0.75, 9.9e-2);
  expectWithin15Percent("MacCormack (semi-Lagrangian)", BuildingBlock::SemiLagrangian, AdvectionScheme::MacCormack,
                        0.75, 1.7e-1);
}

TEST(ZalesakDisc, Figure2_8_SemiLagrangianBuildingBlocksCfl175) {
  expectWithin15Percent("MacCormack (semi-Lagrangian)", BuildingBlock::SemiLagrangian, AdvectionScheme::MacCormack,
                        1.75, 1.5e-1);
}
