// Selle ch. 2.7 (no new extrema with the limiter) and ch. 2.9 (first order next to solids; solid
// values untouched; nothing read through a solid wall), plus MAC-grid and 3D advection against
// exact translations.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "msim/numerics/advection/advector.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

// Square wave on a periodic 1D line (n x 1 grid): the data of Selle's Figure 2.5.
Grid<float, 2> squareWave(const GridSpec<2>& spec) {
  Grid<float, 2> u(spec);
  for (std::size_t i = 0; i < u.count(); ++i) {
    const double x = u.position(u.coord(i)).x();
    u[i] = (x > 0.25 && x < 0.5) ? 1.0f : 0.0f;
  }
  return u;
}

MacGrid<2> uniformFlow(const GridSpec<2>& spec, float ux, float uy) {
  MacGrid<2> v(spec);
  v.component(0).fill(ux);
  v.component(1).fill(uy);
  return v;
}

std::pair<float, float> range(const Grid<float, 2>& g) {
  const auto [lo, hi] = std::minmax_element(g.data().begin(), g.data().end());
  return {*lo, *hi};
}

}  // namespace

TEST(ExtremaLimiter, UnlimitedSchemesOvershootAndLimitedOnesStayInRange) {
  const GridSpec<2> spec(Vec2::Zero(), 1.0 / 100, IVec2(100, 1));
  const MacGrid<2> velocity = uniformFlow(spec, 1.0f, 0.0f);
  for (BuildingBlock block : {BuildingBlock::Upwind, BuildingBlock::SemiLagrangian}) {
    const double cfl = block == BuildingBlock::Upwind ? 0.75 : 1.75;
    for (AdvectionScheme scheme : {AdvectionScheme::BFECC, AdvectionScheme::MacCormack}) {
      for (ExtremaLimiter limiter :
           {ExtremaLimiter::None, ExtremaLimiter::ClampExtrema, ExtremaLimiter::RevertToFirstOrder}) {
        AdvectionSettings s;
        s.block = block;
        s.scheme = scheme;
        s.limiter = limiter;
        Advector<float, 2> advector(spec, s, allPeriodic<2>());
        Grid<float, 2> u = squareWave(spec);
        float lo = 0.0f, hi = 1.0f;
        for (int step = 0; step < 40; ++step) {
          advector.advect(u, velocity, cfl * spec.dx);
          const auto [l, h] = range(u);
          lo = std::min(lo, l);
          hi = std::max(hi, h);
        }
        if (limiter == ExtremaLimiter::None) {
          EXPECT_GT(hi - 1.0f, 1e-2f) << "Figure 2.5: the unlimited scheme should overshoot";
        } else {
          EXPECT_GE(lo, 0.0f);
          EXPECT_LE(hi, 1.0f);
        }
      }
    }
  }
}

// A 2-cell solid wall across a channel flowing in +x at CFL 1.75.
class SolidWall : public ::testing::Test {
 protected:
  static constexpr int kWall = 20;
  const GridSpec<2> spec{Vec2::Zero(), 1.0, IVec2(48, 8)};
  Grid<float, 2> mask{spec, 0.0f};
  MacGrid<2> velocity = uniformFlow(spec, 1.0f, 0.25f);
  Grid<float, 2> field{spec};

  void SetUp() override {
    for (int j = 0; j < 8; ++j) mask(IVec2(kWall, j)) = mask(IVec2(kWall + 1, j)) = 1.0f;
    for (std::size_t i = 0; i < field.count(); ++i) {
      const Vec2 p = field.position(field.coord(i));
      field[i] = static_cast<float>(std::sin(0.7 * p.x()) + 0.3 * std::cos(0.9 * p.y()));
    }
    for (int j = 0; j < 8; ++j) field(IVec2(kWall, j)) = field(IVec2(kWall + 1, j)) = 7.0f;
  }
  Grid<float, 2> advected(Grid<float, 2> f, AdvectionScheme scheme, bool rule) const {
    AdvectionSettings s;
    s.scheme = scheme;
    s.limiter = ExtremaLimiter::None;
    s.firstOrderNearSolids = rule;
    Advector<float, 2> advector(spec, s, AxisBoundaries<2>{AxisBoundary::Clamped, AxisBoundary::Periodic});
    advector.setSolid(mask);
    advector.advect(f, velocity, 1.75);
    return f;
  }
};

TEST_F(SolidWall, SolidValuesStayAndNearSolidSamplesAreFirstOrder) {
  for (AdvectionScheme scheme : {AdvectionScheme::BFECC, AdvectionScheme::MacCormack}) {
    const Grid<float, 2> high = advected(field, scheme, true);
    const Grid<float, 2> unruled = advected(field, scheme, false);
    const Grid<float, 2> first = advected(field, AdvectionScheme::FirstOrder, true);
    int reverted = 0;
    for (int j = 0; j < 8; ++j) {
      EXPECT_EQ(high(IVec2(kWall, j)), 7.0f);
      EXPECT_EQ(high(IVec2(kWall + 1, j)), 7.0f);
      // Downstream of the wall the forward trace of cells kWall+2, kWall+3 lands on solid cells.
      for (int i = kWall + 2; i <= kWall + 3; ++i) {
        EXPECT_EQ(high(IVec2(i, j)), first(IVec2(i, j))) << i << "," << j;
        reverted += unruled(IVec2(i, j)) != first(IVec2(i, j));
      }
      // Far from the wall the second-order value is kept.
      EXPECT_EQ(high(IVec2(kWall + 8, j)), unruled(IVec2(kWall + 8, j)));
      EXPECT_NE(high(IVec2(kWall + 8, j)), first(IVec2(kWall + 8, j)));
    }
    EXPECT_GT(reverted, 0) << "the rule must change something for this test to mean anything";
  }
}

TEST_F(SolidWall, NothingIsReadThroughTheWall) {
  Grid<float, 2> changed = field;
  for (int j = 0; j < 8; ++j)
    for (int i = 0; i < kWall; ++i) changed(IVec2(i, j)) += 5.0f;  // upstream side only
  for (AdvectionScheme scheme : {AdvectionScheme::FirstOrder, AdvectionScheme::BFECC, AdvectionScheme::MacCormack}) {
    const Grid<float, 2> a = advected(field, scheme, true);
    const Grid<float, 2> b = advected(changed, scheme, true);
    for (int j = 0; j < 8; ++j)
      for (int i = kWall; i < 48; ++i) EXPECT_EQ(a(IVec2(i, j)), b(IVec2(i, j))) << i << "," << j;
  }
}

// Each MAC component is carried by the velocity at its own face positions: with a uniform
// diagonal velocity and periodic axes, an integer-cell shift must move every component exactly.
TEST(MacGridAdvection, PeriodicIntegerShiftIsExactIn3D) {
  const GridSpec<3> spec(Vec3::Zero(), 0.5, IVec3(16, 12, 10));
  MacGrid<3> velocity(spec);
  velocity.component(0).fill(1.0f);
  velocity.component(1).fill(-2.0f);
  velocity.component(2).fill(0.5f);
  MacGrid<3> field(spec);
  for (int a = 0; a < 3; ++a) {
    auto& g = field.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      const Vec3 p = g.position(g.coord(i));
      // periodic in every axis over the 8 x 6 x 5 domain
      g[i] = static_cast<float>(a + std::sin(2 * M_PI * p.x() / 8) * std::cos(2 * M_PI * p.y() / 6) +
                                std::sin(2 * M_PI * p.z() / 5));
    }
  }
  const MacGrid<3> initial = field;
  AdvectionSettings s;  // semi-Lagrangian MacCormack, limiter on
  Advector<float, 3> advector(spec, s, allPeriodic<3>());
  advector.advect(field, velocity, 1.0);  // shift (1, -2, 0.5) m = (2, -4, 1) cells
  for (int a = 0; a < 3; ++a) {
    const auto& g = field.component(a);
    const auto& g0 = initial.component(a);
    for (std::size_t i = 0; i < g.count(); ++i) {
      IVec3 c = g.coord(i);
      IVec3 src(c[0] - 2, c[1] + 4, c[2] - 1);
      for (int b = 0; b < 3; ++b) src[b] = ((src[b] % spec.res[b]) + spec.res[b]) % spec.res[b];
      ASSERT_NEAR(g[i], g0(src), 1e-5f) << "component " << a;
    }
  }
}

// A smooth 3D bump translated by a fractional shift in a clamped box: MacCormack must beat the
// first-order semi-Lagrangian error against the exact translated bump by a wide margin.
TEST(ScalarAdvection, MacCormackBeatsFirstOrderIn3D) {
  const GridSpec<3> spec(Vec3::Zero(), 1.0 / 32, IVec3::Constant(32));
  MacGrid<3> velocity(spec);
  velocity.component(0).fill(0.3f);
  velocity.component(1).fill(0.2f);
  velocity.component(2).fill(-0.1f);
  auto bump = [](const Vec3& p) { return std::exp(-(p - Vec3(0.5, 0.5, 0.5)).squaredNorm() / 0.02); };
  double err[2];
  for (int k = 0; k < 2; ++k) {
    AdvectionSettings s;
    s.scheme = k ? AdvectionScheme::MacCormack : AdvectionScheme::FirstOrder;
    Advector<float, 3> advector(spec, s);
    Grid<float, 3> phi(spec);
    for (std::size_t i = 0; i < phi.count(); ++i) phi[i] = static_cast<float>(bump(phi.position(phi.coord(i)) + Vec3(0.15, 0.1, -0.05)));
    const double dt = 0.05;
    for (int n = 0; n < 10; ++n) advector.advect(phi, velocity, dt);  // moves by (0.15, 0.1, -0.05)
    double sum = 0.0;
    for (std::size_t i = 0; i < phi.count(); ++i) sum += std::abs(phi[i] - bump(phi.position(phi.coord(i))));
    err[k] = sum / phi.count();
  }
  EXPECT_LT(err[1], 0.35 * err[0]) << "first order " << err[0] << ", MacCormack " << err[1];
}
