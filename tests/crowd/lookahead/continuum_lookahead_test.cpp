// The continuum lookahead (Golas ch. 3.5): the pyramid of future densities, eq. 3.2's direction
// choice against a brute-force search, and the seed notes' check L9 (the gradient ascent
// converges in fewer than 10 iterations on average over a scene; a density gradient across the
// preferred velocity deflects the agent away from the denser side).
#include <gtest/gtest.h>

#include <cmath>
#include <numeric>
#include <random>
#include <vector>

#include "msim/crowd/lookahead/continuum_lookahead.hpp"
#include "msim/crowd/lookahead/future_density.hpp"

using namespace msim;
using namespace msim::crowd;
using namespace msim::crowd::lookahead;

namespace {

HorizonSchedule schedule(int levels) {
  HorizonSchedule s;
  s.baseStep = 0.01;
  s.levels = levels;
  s.coarsening = 2.0;
  return s;
}

double total(const FutureDensity& f, int level, const Vec2& lo, const Vec2& hi, double cell) {
  // The density integrated over a box that holds every splat: the agent count.
  const double h = cell * std::pow(2.0, level) / 4.0;
  double sum = 0.0;
  for (double y = lo.y() - 3.0 * cell * std::pow(2.0, level); y < hi.y() + 3.0 * cell * std::pow(2.0, level); y += h)
    for (double x = lo.x() - 3.0 * cell * std::pow(2.0, level); x < hi.x() + 3.0 * cell * std::pow(2.0, level); x += h)
      sum += f.density(level, Vec2(x, y)).value * h * h;
  return sum;
}

}  // namespace

TEST(ContinuumLookahead, WalkingSpeedFallsLinearlyToTheFloor) {
  const ContinuumSettings s;  // rho_max 5.5, floor 0.01 m/s
  EXPECT_DOUBLE_EQ(continuumSpeed(0.0, 1.4, s), 1.4);
  EXPECT_DOUBLE_EQ(continuumSpeed(2.75, 1.4, s), 0.7);
  EXPECT_DOUBLE_EQ(continuumSpeed(6.0, 1.4, s), 0.01);
  EXPECT_DOUBLE_EQ(continuumSpeedSlope(2.75, 1.4, s), -1.4 / 5.5);
  EXPECT_EQ(continuumSpeedSlope(6.0, 1.4, s), 0.0);
}

TEST(ContinuumLookahead, PyramidKeepsEveryAgentAndItsExtrapolation) {
  // 200 agents walking at random velocities: each level holds 200 agents, their centre of mass
  // where the agents will be dt_i ahead (a bilinear splat keeps the first moment).
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec2f> x, v;
  for (int i = 0; i < 200; ++i) {
    x.emplace_back(10.0f + 20.0f * u(rng), 10.0f + 20.0f * u(rng));
    v.emplace_back(1.4f * (2.0f * u(rng) - 1.0f), 1.4f * (2.0f * u(rng) - 1.0f));
  }
  const Vec2 lo(0.0, 0.0), hi(40.0, 40.0);
  FutureDensity f;
  const HorizonSchedule s = schedule(8);
  f.build(s, 0.5, lo, hi, x, v);
  ASSERT_EQ(f.levels(), 8);
  for (int level : {0, 3, 8}) {
    EXPECT_NEAR(total(f, level, lo, hi, 0.5), 200.0, 1e-3) << "level " << level;
    Vec2 centre = Vec2::Zero();
    for (std::size_t i = 0; i < x.size(); ++i) centre += f.predicted(level, x[i], v[i]);
    Vec2 expected = Vec2::Zero();
    for (std::size_t i = 0; i < x.size(); ++i) expected += x[i].cast<double>() + s.horizon(level) * v[i].cast<double>();
    EXPECT_LT((centre - expected).norm() / 200.0, 1e-5) << "level " << level;
  }
}

TEST(ContinuumLookahead, UniformCrowdHasItsDensityAndAnAgentDoesNotSeeItself) {
  // Agents on a square lattice 0.7 m apart: 1 / 0.49 = 2.04 per m^2 in the interior, seen by an
  // agent without itself as (n - 1) / n of that on its own footprint; a lone agent sees nothing.
  std::vector<Vec2f> x, v;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) {
      x.emplace_back(1.0f + 0.7f * i, 1.0f + 0.7f * j);
      v.emplace_back(0.0f, 0.0f);
    }
  FutureDensity f;
  f.build(schedule(2), 1.0, Vec2(0.0, 0.0), Vec2(30.0, 30.0), x, v);
  const FutureDensity::Flow flow = f.flow(Vec2(15.2, 14.9));
  EXPECT_NEAR(flow.density, 1.0 / 0.49, 0.1);
  EXPECT_NEAR(flow.speedDeviation, 0.0, 1e-6);
  const Vec2 centre(1.0 + 0.7 * 20, 1.0 + 0.7 * 20);
  const FutureDensity::Density others = f.othersDensity(0, centre);
  EXPECT_NEAR(others.value, 1.0 / 0.49, 0.6);
  EXPECT_LT(others.value, flow.density);
  EXPECT_LT(others.gradient.norm(), 0.2);

  const std::vector<Vec2f> one{Vec2f(5.3f, 6.1f)}, still{Vec2f(0.0f, 0.0f)};
  f.build(schedule(2), 1.0, Vec2(0.0, 0.0), Vec2(10.0, 10.0), one, still);
  const FutureDensity::Density alone = f.othersDensity(0, Vec2(5.3, 6.1));
  EXPECT_NEAR(alone.value, 0.0, 1e-6);
  EXPECT_NEAR(alone.gradient.norm(), 0.0, 1e-5);
  EXPECT_GT(f.density(0, Vec2(5.3, 6.1)).value, 0.2);
}

TEST(ContinuumLookahead, DirectionMatchesABruteForceMaximum) {
  // Eq. 3.2 over the unit disc by sampling it finely (201 radii x 2000 angles), against the projected
  // gradient ascent.
  const ContinuumSettings s;
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  int converged = 0;
  for (int trial = 0; trial < 50; ++trial) {
    const Vec2 vp(1.4 * u(rng), 1.4 * u(rng));
    const Vec2 g(3.0 * u(rng), 3.0 * u(rng));
    const double slope = -1.4 / 5.5;
    const double k = 0.5 * slope * s.planHorizon;
    const auto objective = [&](const Vec2& v) { return vp.dot(v) + k * v.dot(g) * vp.dot(v); };
    double best = -1e9;
    for (int r = 0; r <= 200; ++r)
      for (int a = 0; a < 2000; ++a) {
        const double rho = r / 200.0, theta = 2.0 * M_PI * a / 2000.0;
        best = std::max(best, objective(rho * Vec2(std::cos(theta), std::sin(theta))));
      }
    const DirectionChoice c = bestDirection(vp, g, slope, vp, s);
    converged += c.converged;
    EXPECT_LE(c.direction.norm(), 1.0 + 1e-12);
    EXPECT_LT(c.iterations, 10) << "trial " << trial;
    // The sampling's own resolution: 2 pi / 2000 in angle costs at most |p| (1 + |k||g|) pi^2 / 2000^2.
    EXPECT_GT(objective(c.direction), best - 1e-5 * vp.norm()) << "trial " << trial;
  }
  EXPECT_EQ(converged, 50);
}

TEST(ContinuumLookahead, L9DenserSideDeflects) {
  // The density rises to the left of the preferred velocity: the agent turns right, and the other
  // way round; without a gradient it walks straight along v_p.
  const ContinuumSettings s;
  const Vec2 vp(1.4, 0.0);
  const double slope = -1.4 / 5.5;
  const DirectionChoice left = bestDirection(vp, Vec2(0.0, 2.0), slope, vp, s);
  const DirectionChoice right = bestDirection(vp, Vec2(0.0, -2.0), slope, vp, s);
  EXPECT_LT(left.direction.y(), -0.05);
  EXPECT_GT(right.direction.y(), 0.05);
  EXPECT_GT(left.direction.x(), 0.0);
  const DirectionChoice flat = bestDirection(vp, Vec2::Zero(), slope, vp, s);
  EXPECT_NEAR((flat.direction - Vec2(1.0, 0.0)).norm(), 0.0, 1e-12);
}

TEST(ContinuumLookahead, L9ConvergesInFewerThanTenIterationsOverAScene) {
  // Two groups of 500 walking at each other (the crossing), eight levels each: the mean number of
  // ascent iterations per solve (agent and level) stays below the seed's 10.
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(0.0f, 1.0f);
  std::vector<Vec2f> x, v, vp;
  for (int i = 0; i < 1000; ++i) {
    const bool east = i < 500;
    x.emplace_back((east ? 5.0f : 25.0f) + 10.0f * u(rng), 5.0f + 20.0f * u(rng));
    v.emplace_back(east ? 1.3f : -1.3f, 0.2f * (u(rng) - 0.5f));
    vp.emplace_back(east ? 1.4f : -1.4f, 0.0f);
  }
  FutureDensity f;
  f.build(schedule(8), 1.0, Vec2(0.0, 0.0), Vec2(40.0, 30.0), x, v);
  const ContinuumSettings s;
  long iterations = 0, solves = 0;
  int deflected = 0;
  for (std::size_t i = 0; i < x.size(); ++i) {
    const CascadeResult r = continuumLookahead(f, s, x[i], v[i], vp[i], 1.4, 8, 0);
    iterations += r.iterations;
    solves += r.solves;
    if (std::abs(r.velocity.y()) > 0.05) ++deflected;
    EXPECT_LE(r.velocity.norm(), 1.4 + 1e-9);
  }
  EXPECT_EQ(solves, 9000);
  testing::Test::RecordProperty("iterations_per_solve", std::to_string(double(iterations) / double(solves)));
  EXPECT_LT(double(iterations) / double(solves), 10.0);
  EXPECT_GT(deflected, 50);  // the far levels see the other group coming and steer around it
}

TEST(ContinuumLookahead, CascadeLeavesLevelZeroToTheLocalModel) {
  // lowest = 1: the preferred speed is kept (the UIC or ORCA slows the agent, not the lookahead);
  // depth 0 with lowest 1 asks nothing and returns v_p.
  std::vector<Vec2f> x{Vec2f(10.0f, 10.0f), Vec2f(14.0f, 10.5f)}, v{Vec2f(1.0f, 0.0f), Vec2f(-1.0f, 0.0f)};
  FutureDensity f;
  f.build(schedule(8), 1.0, Vec2(0.0, 0.0), Vec2(30.0, 30.0), x, v);
  const ContinuumSettings s;
  const CascadeResult far = continuumLookahead(f, s, x[0], v[0], Vec2f(1.2f, 0.0f), 1.4, 8, 1);
  EXPECT_EQ(far.solves, 8);
  EXPECT_NEAR(far.velocity.norm(), 1.2, 1e-6);
  const CascadeResult none = continuumLookahead(f, s, x[0], v[0], Vec2f(1.2f, 0.0f), 1.4, 0, 1);
  EXPECT_EQ(none.solves, 0);
  EXPECT_NEAR((none.velocity - Vec2(1.2, 0.0)).norm(), 0.0, 1e-7);
}
