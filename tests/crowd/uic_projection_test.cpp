// UIC projection (Narain 2011, ch. 4.3.2-4.4.3) against independent expectations: conservation of
// the splat, uniform flows reproduced, sparse crowds untouched (p = 0), the density cap f rho_max
// and the KKT conditions of the outer LCP on converging crowds, half-covered cells capped at
// rho_max / 2, warm starts, and an iteration count independent of the number of sparse agents.
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include <algorithm>
#include <cmath>
#include <stdexcept>
#include <vector>

#include "msim/core/error.hpp"
#include "msim/core/rng.hpp"
#include "msim/crowd/free_area.hpp"
#include "msim/crowd/uic_projection.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

constexpr double kRhoMax = 4.0;

struct Crowd {
  std::vector<Vec2f> x, v;
  std::vector<float> speed;
  std::vector<Vec2f> out;
  void add(const Vec2f& p, const Vec2f& pv) {
    x.push_back(p);
    v.push_back(pv);
    speed.push_back(pv.norm());
    out.emplace_back(Vec2f::Zero());
  }
};

GridSpec<2> grid20() { return GridSpec<2>(Vec2(0, 0), 1.0, IVec2(20, 20)); }

// Agents on a square lattice of the given density over [lo, hi], all walking at `speed` towards
// `target`.
void convergingLattice(Crowd& c, const Vec2f& lo, const Vec2f& hi, double density, const Vec2f& target,
                       float speed) {
  const float h = static_cast<float>(1.0 / std::sqrt(density));
  for (float y = lo.y() + h / 2; y < hi.y(); y += h)
    for (float x = lo.x() + h / 2; x < hi.x(); x += h) {
      const Vec2f d = target - Vec2f(x, y);
      c.add(Vec2f(x, y), d.norm() > 1e-6f ? Vec2f(d.normalized() * speed) : Vec2f(speed, 0.0f));
    }
}

UicSettings settings() {
  UicSettings s;
  s.rhoMax = kRhoMax;
  return s;
}

}  // namespace

TEST(UicProjection, SplatConservesAgentCount) {
  Rng rng(3);
  Crowd c;
  for (int i = 0; i < 1000; ++i)
    c.add(Vec2f(float(rng.uniform(0.0, 20.0)), float(rng.uniform(0.0, 20.0))), Vec2f(1.0f, 0.0f));
  c.add(Vec2f(20.0f, 20.0f), Vec2f(1.0f, 0.0f));  // on the upper corner
  UicProjection uic(grid20(), settings());
  Grid<float, 2> f(grid20(), 1.0f);
  uic.project(c.x, c.v, c.speed, f, 0.1, c.out);
  double cells = 0.0, xFaces = 0.0, yFaces = 0.0;
  for (float r : uic.density().data()) cells += r;
  for (float r : uic.faceDensity().component(0).data()) xFaces += r;
  for (float r : uic.faceDensity().component(1).data()) yFaces += r;
  EXPECT_NEAR(cells, 1001.0, 1e-3);  // dx = 1: density sums to the count
  EXPECT_NEAR(xFaces, 1001.0, 1e-3);
  EXPECT_NEAR(yFaces, 1001.0, 1e-3);
  // The predicted density conserves the agents too (walls: no flux).
  double predicted = 0.0;
  for (float r : uic.predictedDensity().data()) predicted += r;
  EXPECT_NEAR(predicted, 1001.0, 1e-2);
}

TEST(UicProjection, SparseUniformCrowdIsUntouched) {
  Rng rng(5);
  Crowd c;
  const Vec2f pv(0.8f, -0.3f);
  for (int i = 0; i < 60; ++i)
    c.add(Vec2f(float(rng.uniform(3.0, 17.0)), float(rng.uniform(3.0, 17.0))), pv);
  UicProjection uic(grid20(), settings());
  Grid<float, 2> f(grid20(), 1.0f);
  const UicStats& s = uic.project(c.x, c.v, c.speed, f, 0.25, c.out);
  EXPECT_EQ(s.activeCells, 0);
  EXPECT_EQ(s.innerIterations + s.outerIterations, 0);
  for (float p : uic.pressure().data()) EXPECT_EQ(p, 0.0f);
  // v~ on every face that carries agents is the common preferred velocity (eq. 4.2).
  for (int a = 0; a < 2; ++a)
    for (std::size_t i = 0; i < uic.preferredVelocity().component(a).count(); ++i)
      if (uic.faceDensity().component(a)[i] > 0.0f) {
        ASSERT_NEAR(uic.preferredVelocity().component(a)[i], pv[a], 1e-6);
      }
  for (const Vec2f& v : c.out) {
    EXPECT_NEAR(v.x(), pv.x(), 1e-5);
    EXPECT_NEAR(v.y(), pv.y(), 1e-5);
  }
}

TEST(UicProjection, RenormUsesEachGroupsOwnSpeed) {
  // Two sparse groups far apart, walking along +x at 1 and 2 m/s: v_max on the faces is each
  // group's speed, so the corrected field keeps it.
  Crowd c;
  for (int i = 0; i < 5; ++i)
    for (int j = 0; j < 5; ++j) {
      c.add(Vec2f(3.0f + 0.7f * i, 3.0f + 0.7f * j), Vec2f(1.0f, 0.0f));
      c.add(Vec2f(12.0f + 0.7f * i, 12.0f + 0.7f * j), Vec2f(2.0f, 0.0f));
    }
  UicProjection uic(grid20(), settings());
  Grid<float, 2> f(grid20(), 1.0f);
  uic.project(c.x, c.v, c.speed, f, 0.1, c.out);
  const auto& vx = uic.velocity().component(0);
  const auto& rho = uic.faceDensity().component(0);
  int checked = 0;
  for (int j = 1; j < 19; ++j)
    for (int i = 1; i < 20; ++i) {
      const IVec2 face(i, j);
      if (rho(face) == 0.0f) continue;
      EXPECT_NEAR(vx(face), i < 10 ? 1.0f : 2.0f, 1e-5) << i << " " << j;
      ++checked;
    }
  EXPECT_GE(checked, 40);
  for (std::size_t i = 0; i < c.x.size(); ++i) EXPECT_NEAR((c.out[i] - c.v[i]).norm(), 0.0f, 1e-5);
}

TEST(UicProjection, ConvergingCrowdIsCappedAndSatisfiesKkt) {
  Crowd c;
  convergingLattice(c, Vec2f(4, 4), Vec2f(16, 16), 0.9 * kRhoMax, Vec2f(10.0f, 10.0f), 1.4f);
  UicProjection uic(grid20(), settings());
  Grid<float, 2> f(grid20(), 1.0f);
  const UicStats& s = uic.project(c.x, c.v, c.speed, f, 0.25, c.out);
  EXPECT_TRUE(s.converged);
  EXPECT_GT(s.activeCells, 0);
  EXPECT_LE(s.maxRatioAfter, 1.05);
  const double tol = 0.02 * kRhoMax;
  for (std::size_t k = 0; k < uic.pressure().count(); ++k) {
    const double p = uic.pressure()[k];
    const double sigma = kRhoMax - uic.predictedDensity()[k];
    EXPECT_GE(p, 0.0);
    EXPECT_GE(sigma, -tol) << "cell " << k;
    if (p > 0.0) {
      EXPECT_LE(std::abs(sigma), tol) << "cell " << k << " p " << p;
    }
  }
  // Agents in the saturated core slow down: the mean inward speed there drops below 0.7 m/s.
  double inward = 0.0;
  int core = 0;
  for (std::size_t i = 0; i < c.x.size(); ++i)
    if ((c.x[i] - Vec2f(10, 10)).norm() < 2.0f) {
      inward += c.out[i].dot(Vec2f(Vec2f(10, 10) - c.x[i]).normalized());
      ++core;
    }
  EXPECT_LT(inward / core, 0.5 * 1.4);
}

TEST(UicProjection, HalfCoveredCellsHoldHalfTheDensity) {
  // A wall occupying the left half of column 12; the crowd walks into it for 20 steps.
  const GridSpec<2> g = grid20();
  FreeArea fa(g);
  fa.addStaticObstacle(rectangle(Vec2(12.0, 0.0), Vec2(12.5, 20.0)));
  Crowd c;
  convergingLattice(c, Vec2f(3, 2), Vec2f(11.5f, 18), 0.8 * kRhoMax, Vec2f(1000.0f, 10.0f), 1.4f);
  UicProjection uic(g, settings());
  const double dt = 0.2;
  int constrained = 0;
  for (int step = 0; step < 20; ++step) {
    for (std::size_t i = 0; i < c.x.size(); ++i) c.v[i] = Vec2f(1.4f, 0.0f);
    const UicStats& s = uic.project(c.x, c.v, c.speed, fa.fraction(), dt, c.out);
    ASSERT_TRUE(s.converged);
    for (int j = 0; j < 20; ++j) {
      const float rho = uic.predictedDensity()(IVec2(12, j));
      ASSERT_LE(rho, 0.5 * kRhoMax * 1.05) << "step " << step << " row " << j;
      constrained += uic.pressure()(IVec2(12, j)) > 0.0f;
    }
    for (std::size_t i = 0; i < c.x.size(); ++i) {
      c.x[i] += c.out[i] * float(dt);
      c.x[i] = c.x[i].cwiseMax(Vec2f::Zero()).cwiseMin(Vec2f::Constant(20.0f));
    }
  }
  EXPECT_GT(constrained, 0);  // the cap was reached, not just respected
}

TEST(UicProjection, WarmStartReducesIterations) {
  Crowd c;
  convergingLattice(c, Vec2f(4, 4), Vec2f(16, 16), 0.95 * kRhoMax, Vec2f(10.0f, 10.0f), 1.4f);
  Grid<float, 2> f(grid20(), 1.0f);
  const double dt = 0.1;
  UicProjection warm(grid20(), settings());
  int warmIterations = 0, coldIterations = 0;
  for (int step = 0; step < 10; ++step) {
    const UicStats w = warm.project(c.x, c.v, c.speed, f, dt, c.out);
    ASSERT_GT(w.activeCells, 0);
    UicProjection cold(grid20(), settings());
    std::vector<Vec2f> coldOut(c.out.size());
    const UicStats k = cold.project(c.x, c.v, c.speed, f, dt, coldOut);
    if (step > 0) {
      warmIterations += w.innerIterations + w.outerIterations;
      coldIterations += k.innerIterations + k.outerIterations;
    }
    for (std::size_t i = 0; i < c.x.size(); ++i) c.x[i] += c.out[i] * float(dt);
  }
  EXPECT_LT(warmIterations, coldIterations);
}

TEST(UicProjection, IterationsDoNotDependOnSparseAgents) {
  Crowd base;
  convergingLattice(base, Vec2f(2, 2), Vec2f(10, 10), 0.95 * kRhoMax, Vec2f(6.0f, 6.0f), 1.4f);
  Crowd more = base;
  // A lattice of 0.3 rho_max walking up, away from the dense block (a random sprinkle would hold
  // dense clusters of its own).
  convergingLattice(more, Vec2f(13, 0), Vec2f(20, 20), 0.3 * kRhoMax, Vec2f(16.5f, 1e4f), 0.5f);
  ASSERT_GT(more.x.size(), base.x.size() + 150);
  Grid<float, 2> f(grid20(), 1.0f);
  UicProjection a(grid20(), settings()), b(grid20(), settings());
  const UicStats sa = a.project(base.x, base.v, base.speed, f, 0.25, base.out);
  const UicStats sb = b.project(more.x, more.v, more.speed, f, 0.25, more.out);
  EXPECT_GT(sa.activeCells, 0);
  EXPECT_EQ(sa.activeCells, sb.activeCells);
  EXPECT_NEAR(sa.innerIterations, sb.innerIterations, 2);
  EXPECT_NEAR(sa.outerIterations, sb.outerIterations, 2);
}

// The fused splat, the QP on the crowd's box (120x120 cells, large enough for the parallel MPRGP
// loops) and the gather give bitwise the same result on one thread as on all of them.
TEST(UicProjection, ResultDoesNotDependOnThreadCount) {
  const GridSpec<2> g(Vec2(0, 0), 1.0, IVec2(128, 128));
  Crowd base;
  convergingLattice(base, Vec2f(4, 4), Vec2f(124, 124), 0.9 * kRhoMax, Vec2f(64.0f, 64.0f), 1.4f);
  const Grid<float, 2> f(g, 1.0f);
  auto run = [&](int threads) {
    tbb::global_control limit(tbb::global_control::max_allowed_parallelism, threads);
    Crowd c = base;
    UicProjection uic(g, settings());
    for (int step = 0; step < 3; ++step) {
      uic.project(c.x, c.v, c.speed, f, 0.1, c.out);
      for (std::size_t i = 0; i < c.x.size(); ++i) c.x[i] += 0.1f * c.out[i];
    }
    std::vector<float> state(uic.pressure().data());
    for (const Vec2f& v : c.out) state.insert(state.end(), {v.x(), v.y()});
    return std::make_pair(state, uic.stats().activeCells);
  };
  const auto one = run(1), many = run(4);
  EXPECT_GT(one.second, 0);
  EXPECT_EQ(one.second, many.second);
  ASSERT_EQ(one.first.size(), many.first.size());
  EXPECT_TRUE(one.first == many.first);
}

TEST(UicProjection, RejectsBadInput) {
  UicSettings bad = settings();
  bad.rhoMax = 0.0;
  EXPECT_THROW(UicProjection(grid20(), bad), std::invalid_argument);
  UicProjection uic(grid20(), settings());
  Grid<float, 2> f(grid20(), 1.0f);
  Crowd c;
  c.add(Vec2f(5, 5), Vec2f(1, 0));
  c.add(Vec2f(25, 5), Vec2f(1, 0));  // outside
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, f, 0.1, c.out), InputError);
  c.x[1] = Vec2f(5, NAN);
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, f, 0.1, c.out), InputError);
  c.x[1] = Vec2f(6, 6);
  c.v[1] = Vec2f(INFINITY, 0);
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, f, 0.1, c.out), InputError);
  c.v[1] = Vec2f(1, 0);
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, f, 0.0, c.out), InputError);
  c.speed.pop_back();
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, f, 0.1, c.out), InputError);
  c.speed.push_back(1.0f);
  Grid<float, 2> wrong(GridSpec<2>(Vec2(0, 0), 1.0, IVec2(10, 10)), 1.0f);
  EXPECT_THROW(uic.project(c.x, c.v, c.speed, wrong, 0.1, c.out), InputError);
  EXPECT_NO_THROW(uic.project(c.x, c.v, c.speed, f, 0.1, c.out));
}
