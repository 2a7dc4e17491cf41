// ORCA (van den Berg et al. 2011): head-on swap, antipodal circle swap, a static wall, the speed
// limit, the free agent, and the least-penetration program of the infeasible case.
#include <cmath>
#include <iostream>

#include <Eigen/Geometry>
#include <gtest/gtest.h>
#include <tbb/global_control.h>

#include "msim/crowd/orca.hpp"

namespace msim::crowd {
namespace {

struct RunStats {
  double minRatio = 1e30;      // min |x_i - x_j| / d_min over all steps
  double minObstacle = 1e30;   // min (distance to obstacle - radius) over all steps
  double maxSpeedRatio = 0.0;  // max |v| / maxSpeed
};

// Walks the ORCA agents to their goals: preferred velocity towards the goal at full speed,
// slowing to arrive, explicit Euler positions. A tiny per-agent turn of the preferred velocity
// (up to 0.05 rad, varying) breaks perfectly symmetric deadlocks, which ORCA by itself cannot resolve.
RunStats simulate(Agents& a, const std::vector<Vec2f>& goals, const std::vector<Polygon>& obstacles, int steps,
             float dt = 0.05f) {
  OrcaParams params;
  const StaticObstacles obst(obstacles, 1.4f * params.timeHorizonObst + 0.5f);
  OrcaSolver solver;
  std::vector<Vec2f> v(a.size());
  RunStats run;
  for (int s = 0; s < steps; ++s) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Vec2f d = goals[i] - a.position[i];
      const float len = d.norm();
      const Vec2f pref = len > 0 ? Vec2f(d * std::min(a.maxSpeed[i], len / dt) / len) : Vec2f::Zero();
      const float turn = 5e-2f * std::sin(static_cast<float>(i) * 2.4f + 0.7f * static_cast<float>(s));
      a.preferredVelocity[i] = Eigen::Rotation2Df(turn) * pref;
    }
    solver.computeVelocities(a, obst, params, dt, v);
    for (std::size_t i = 0; i < a.size(); ++i) {
      run.maxSpeedRatio = std::max(run.maxSpeedRatio, static_cast<double>(v[i].norm() / a.maxSpeed[i]));
      a.velocity[i] = v[i];
      a.position[i] += dt * v[i];
    }
    for (std::size_t i = 0; i < a.size(); ++i) {
      for (std::size_t j = i + 1; j < a.size(); ++j)
        run.minRatio = std::min(run.minRatio, static_cast<double>((a.position[i] - a.position[j]).norm() /
                                                                  (a.radius[i] + a.radius[j])));
      for (const auto& poly : obstacles)
        run.minObstacle = std::min(run.minObstacle, signedDistance(poly, a.position[i].cast<double>()) - a.radius[i]);
    }
  }
  return run;
}

Agents orcaAgents(const std::vector<Vec2f>& starts, float radius = 0.3f) {
  Agents a;
  for (const auto& x : starts) {
    AgentSpec s;
    s.position = x;
    s.radius = radius;
    s.model = AgentModel::Orca;
    a.add(s);
  }
  return a;
}

double maxGoalError(const Agents& a, const std::vector<Vec2f>& goals) {
  double e = 0;
  for (std::size_t i = 0; i < a.size(); ++i) e = std::max(e, static_cast<double>((a.position[i] - goals[i]).norm()));
  return e;
}

TEST(Orca, FreeAgentWalksItsPreferredVelocity) {
  Agents a = orcaAgents({Vec2f(0, 0)});
  a.preferredVelocity[0] = Vec2f(0.7f, -0.9f);
  std::vector<Vec2f> v(1);
  OrcaSolver().computeVelocities(a, StaticObstacles(), OrcaParams(), 0.1f, v);
  EXPECT_EQ(v[0], Vec2f(0.7f, -0.9f));
}

TEST(Orca, HeadOnSwap) {
  const std::vector<Vec2f> goals{Vec2f(5, 0), Vec2f(-5, 0)};
  Agents a = orcaAgents({Vec2f(-5, 0), Vec2f(5, 0)});
  const RunStats run = simulate(a, goals, {}, 400);
  std::cout << "[ measure ] head-on: min distance / d_min " << run.minRatio << ", goal error "
            << maxGoalError(a, goals) << " m, max |v|/vmax " << run.maxSpeedRatio << "\n";
  EXPECT_GE(run.minRatio, 0.999);
  EXPECT_LT(maxGoalError(a, goals), 0.05);
  EXPECT_LE(run.maxSpeedRatio, 1.0 + 1e-5);
}

TEST(Orca, CircleAntipodalSwap) {
  for (int n : {8, 16}) {
    std::vector<Vec2f> starts, goals;
    for (int k = 0; k < n; ++k) {
      const float phi = 6.2831853f * k / n;
      starts.emplace_back(6.0f * std::cos(phi), 6.0f * std::sin(phi));
      goals.push_back(-starts.back());
    }
    Agents a = orcaAgents(starts);
    const RunStats run = simulate(a, goals, {}, 1200);
    std::cout << "[ measure ] circle of " << n << ": min distance / d_min " << run.minRatio << ", goal error "
              << maxGoalError(a, goals) << " m, max |v|/vmax " << run.maxSpeedRatio << "\n";
    EXPECT_GE(run.minRatio, 0.99);
    EXPECT_LT(maxGoalError(a, goals), 0.05);
    EXPECT_LE(run.maxSpeedRatio, 1.0 + 1e-5);
  }
}

TEST(Orca, SlidesAroundWallCornerWithoutEntering) {
  // The straight line to the goal clips the wall's corner: the agent must slide around it.
  const std::vector<Polygon> wall{rectangle(Vec2(-0.2, -3.0), Vec2(0.2, 1.0))};
  const std::vector<Vec2f> goals{Vec2f(3.0f, 1.6f), Vec2f(0.0f, -0.4f)};
  Agents a = orcaAgents({Vec2f(-3.0f, 0.5f), Vec2f(-4.0f, -0.4f)});  // the second walks into the wall
  const RunStats run = simulate(a, goals, wall, 300);
  std::cout << "[ measure ] wall: min (distance to wall - radius) " << run.minObstacle << " m, corner goal error "
            << (a.position[0] - goals[0]).norm() << " m\n";
  EXPECT_GE(run.minObstacle, -1e-3);
  EXPECT_LT((a.position[0] - goals[0]).norm(), 0.05);
  EXPECT_LE(run.maxSpeedRatio, 1.0 + 1e-5);
}

TEST(Orca, DenseCrowdIndependentOfThreadCountAndNeighbourLayout) {
  // 20k ORCA agents at 2 per m^2, mixed with UIC agents: the same velocities with one thread and
  // with all, and after the agents are stored in another order (the neighbours are the same
  // closest ones, ties by agent index only, which a reversal would change, so no ties here).
  std::vector<Vec2f> starts;
  std::uint32_t h = 12345;
  auto next = [&] {
    h = h * 1664525u + 1013904223u;
    return static_cast<float>(h >> 8) / 16777216.0f;
  };
  for (int k = 0; k < 20000; ++k) starts.emplace_back(100.0f * next(), 100.0f * next());
  Agents a = orcaAgents(starts, 0.25f);
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float phi = 6.2831853f * next();
    a.preferredVelocity[i] = 1.2f * Vec2f(std::cos(phi), std::sin(phi));
    a.velocity[i] = 0.8f * a.preferredVelocity[i];
    if (i % 7 == 0) a.model[i] = AgentModel::Uic;
  }
  OrcaParams params;
  params.neighbourDist = 2.0f;
  std::vector<Vec2f> v1(a.size(), Vec2f::Zero()), v2(a.size(), Vec2f::Zero());
  OrcaSolver solver;
  {
    tbb::global_control one(tbb::global_control::max_allowed_parallelism, 1);
    solver.computeVelocities(a, StaticObstacles(), params, 0.1f, v1);
  }
  solver.computeVelocities(a, StaticObstacles(), params, 0.1f, v2);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(v1[i], v2[i]) << i;
  Agents r;  // the same agents in reverse order
  for (std::size_t i = a.size(); i-- > 0;) {
    const std::size_t k = r.add(a.spec(i));
    r.velocity[k] = a.velocity[i];
    r.preferredVelocity[k] = a.preferredVelocity[i];
  }
  std::vector<Vec2f> v3(a.size(), Vec2f::Zero());
  solver.computeVelocities(r, StaticObstacles(), params, 0.1f, v3);
  for (std::size_t i = 0; i < a.size(); ++i) ASSERT_EQ(v1[i], v3[a.size() - 1 - i]) << i;
  std::size_t slowed = 0;
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.model[i] == AgentModel::Uic) {
      EXPECT_EQ(v1[i], Vec2f::Zero());  // untouched
      continue;
    }
    EXPECT_LE(v1[i].norm(), a.maxSpeed[i] * (1.0f + 1e-5f));
    if ((v1[i] - a.preferredVelocity[i]).norm() > 1e-3f) ++slowed;
  }
  EXPECT_GT(slowed, a.size() / 10);  // a dense crowd: many agents deviate from their preference
}

TEST(Orca, InfeasibleProgramMinimisesLargestPenetration) {
  // v.x >= 1 and v.x <= -1 cannot both hold: the best compromise is v.x = 0 (1 m/s into each).
  const std::vector<HalfPlane> planes{{Vec2f(1, 0), Vec2f(1, 0)}, {Vec2f(-1, 0), Vec2f(-1, 0)}};
  std::vector<HalfPlane> scratch;
  const Vec2f v = solveOrcaProgram(planes, 0, Vec2f(0.5f, 0.3f), 2.0f, scratch);
  EXPECT_NEAR(v.x(), 0.0f, 1e-5f);
  EXPECT_LE(v.norm(), 2.0f + 1e-5f);
}

}  // namespace
}  // namespace msim::crowd
