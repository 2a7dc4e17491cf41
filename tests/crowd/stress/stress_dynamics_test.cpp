// The stress model's agent motion (Golas eqs. 4.6-4.7, midpoint integration): free agents relax
// to their collision-free velocity over tau as the exponential says; no agent ever accelerates
// faster than a_max (check T6 over whole steps); discomfort spreads a crowd packed past the
// critical density; friction makes sheared layers of a packed crowd move together sooner.
#include <gtest/gtest.h>

#include <cmath>
#include <random>
#include <vector>

#include "msim/crowd/stress/crowd_pressure.hpp"
#include "msim/crowd/stress/stress_dynamics.hpp"

using namespace msim;
using namespace msim::crowd;
using namespace msim::crowd::stress;

namespace {

void lattice(double a, double x0, double x1, double y0, double y1, std::vector<Vec2f>& x) {
  for (double y = y0 + 0.5 * a; y < y1; y += a)
    for (double px = x0 + 0.5 * a; px < x1; px += a) x.emplace_back(static_cast<float>(px), static_cast<float>(y));
}

const GridSpec<2> kGrid(Vec2(0.0, 0.0), 0.5, IVec<2>(40, 40));  // 20 x 20 m of 0.5 m cells

}  // namespace

TEST(CrowdStressDynamics, FreeAgentsRelaxExponentially) {
  // 25 agents 3 m apart (well below rho_crit) from rest towards 1.2 m/s over tau = 0.5 s:
  // v(1 s) = 1.2 (1 - e^-2).
  std::vector<Vec2f> x, v, cf;
  lattice(3.0, 2.0, 17.0, 2.0, 17.0, x);
  v.assign(x.size(), Vec2f::Zero());
  cf.assign(x.size(), Vec2f(1.2f, 0.0f));
  StressSettings settings;
  settings.relaxation = 0.5;
  StressDynamics d(kGrid, settings);
  const Grid<float, 2> free(kGrid, 1.0f);
  for (int s = 0; s < 20; ++s) d.step(x, v, cf, free, 0.05);
  for (const Vec2f& u : v) {
    EXPECT_NEAR(u.x(), 1.2 * (1.0 - std::exp(-2.0)), 0.01 * 1.2);
    EXPECT_NEAR(u.y(), 0.0, 1e-6);
  }
}

TEST(CrowdStressDynamics, T6NoAgentAcceleratesFasterThanTheLimit) {
  // A crowd packed at 6.25 /m^2 with random velocities, pushed and rubbed for 20 steps.
  std::vector<Vec2f> x, v, cf;
  lattice(0.4, 4.0, 16.0, 4.0, 16.0, x);
  std::mt19937 rng(5);
  std::normal_distribution<float> n(0.0f, 1.0f);
  for (std::size_t k = 0; k < x.size(); ++k) {
    v.emplace_back(n(rng), n(rng));
    cf.emplace_back(1.3f, 0.0f);
  }
  StressSettings settings;
  StressDynamics d(kGrid, settings);
  const Grid<float, 2> free(kGrid, 1.0f);
  int solves = 0, unconverged = 0;
  for (int s = 0; s < 20; ++s) {
    const std::vector<Vec2f> before = v;
    const StressStepStats st = d.step(x, v, cf, free, 0.05);
    solves += st.solves;
    unconverged += st.unconverged;
    for (std::size_t k = 0; k < v.size(); ++k)
      ASSERT_LE((v[k] - before[k]).norm() / 0.05, settings.maxAcceleration * (1.0 + 1e-5)) << "step " << s << " agent " << k;
  }
  EXPECT_EQ(solves, 40);
  EXPECT_EQ(unconverged, 0);
}

TEST(CrowdStressDynamics, DiscomfortSpreadsAnOverpackedCrowd) {
  // 7.7 /m^2 in a 6 x 6 m square, nobody wanting to go anywhere: discomfort pushes the crowd apart
  // until the densest cell is below the yield density.
  std::vector<Vec2f> x, v, cf;
  lattice(0.36, 7.0, 13.0, 7.0, 13.0, x);
  v.assign(x.size(), Vec2f::Zero());
  cf.assign(x.size(), Vec2f::Zero());
  StressDynamics d(kGrid, {});
  const Grid<float, 2> free(kGrid, 1.0f);
  const auto densest = [&] {
    float m = 0.0f;
    for (std::size_t c = 0; c < d.fields().density().count(); ++c) m = std::max(m, d.fields().density()[c]);
    return m;
  };
  d.step(x, v, cf, free, 0.05);
  const float start = densest();
  for (int s = 0; s < 60; ++s) d.step(x, v, cf, free, 0.05);
  EXPECT_GT(start, 7.0f);
  EXPECT_LT(densest(), 5.5f);
}

TEST(CrowdStressDynamics, FrictionLocksShearedLayersTogether) {
  // A packed crowd (6.25 /m^2) whose upper half walks east at 0.6 m/s and lower half west, each
  // agent wanting to keep its velocity: with friction the halves' speed difference falls far more
  // in 1 s than with discomfort alone (alpha = 0, Fig. 4.10's control).
  const auto run = [](double frictionMax) {
    std::vector<Vec2f> x, v, cf;
    lattice(0.4, 2.0, 18.0, 6.0, 14.0, x);
    for (const Vec2f& p : x) v.emplace_back(p.y() > 10.0f ? 0.6f : -0.6f, 0.0f);
    cf = v;
    StressSettings settings;
    settings.laws.frictionMax = frictionMax;
    StressDynamics d(kGrid, settings);
    const Grid<float, 2> free(kGrid, 1.0f);
    for (int s = 0; s < 20; ++s) d.step(x, v, cf, free, 0.05);
    double upper = 0.0, lower = 0.0;
    int nu = 0, nl = 0;
    for (std::size_t k = 0; k < x.size(); ++k)
      if (cf[k].x() > 0.0f) upper += v[k].x(), ++nu;
      else lower += v[k].x(), ++nl;
    return upper / nu - lower / nl;
  };
  const double withFriction = run(0.75), without = run(0.0);
  testing::Test::RecordProperty("difference_with_friction", std::to_string(withFriction));
  testing::Test::RecordProperty("difference_without", std::to_string(without));
  EXPECT_GT(without, 1.0);
  EXPECT_LT(withFriction, 0.8 * without);
}

// The step the stress model needs (crowd.turbulence.max_step, 0.01 s): a crowd packed at 5 /m^2
// (random places) filling a closed room and wanting to stay where it is. The discomfort is stiff
// there (its waves run at sqrt(g') = 10 m/s at 5 /m^2, 190 m/s just below the yield density), so a
// step's clamped acceleration overshoots and turns, and agents shake by about a_max dt on top of
// the crowd's own sloshing towards even density. The scene-mean temporal pressure (3 s window)
// after 4 s falls as the step shrinks; with 0.01 s it lies closer to the 0.005 s value than half
// of what 0.05 s (the crowd's usual step) adds.
TEST(CrowdStressDynamics, TheDefaultStepIsWhereTheCrowdPressureSettles) {
  const GridSpec<2> grid(Vec2(0.0, 0.0), 1.0, IVec<2>(24, 24));
  const auto meanPressure = [&](double dt) {
    std::vector<Vec2f> x, v, cf;
    std::mt19937 rng(3);
    std::uniform_real_distribution<float> u(1.0f, 23.0f);
    for (int k = 0; k < 2420; ++k) x.emplace_back(u(rng), u(rng));  // 5 /m^2 filling a 22 x 22 m room
    v.assign(x.size(), Vec2f::Zero());
    cf.assign(x.size(), Vec2f::Zero());
    StressDynamics d(grid, {});
    Grid<float, 2> free(grid, 0.0f);  // the room's walls: the ring of cells around it
    for (int j = 1; j < 23; ++j)
      for (int i = 1; i < 23; ++i) free(IVec<2>(i, j)) = 1.0f;
    CrowdWindows windows(grid, 1);
    TemporalPressure pressure(grid, 3.0);
    Grid<float, 2> p(grid);
    const int steps = static_cast<int>(std::lround(4.0 / dt));
    for (int s = 0; s < steps; ++s) {
      d.step(x, v, cf, free, dt);
      windows.gather(x, v);
      pressure.add(windows, dt);
    }
    pressure.pressure(p);
    return pressure.meanWhereOccupied(p);
  };
  const double usual = meanPressure(0.05), standard = meanPressure(0.01), fine = meanPressure(0.005);
  testing::Test::RecordProperty("pressure_at_0_05_s", std::to_string(usual));
  testing::Test::RecordProperty("pressure_at_0_01_s", std::to_string(standard));
  testing::Test::RecordProperty("pressure_at_0_005_s", std::to_string(fine));
  EXPECT_GT(usual, standard);
  EXPECT_GT(standard, fine);
  EXPECT_LT(standard - fine, 0.5 * (usual - fine));
}
