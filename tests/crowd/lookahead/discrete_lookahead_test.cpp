// The discrete lookahead on ORCA (Golas ch. 3.6): level 0 keeps ORCA's guarantee (the seed notes'
// check L2), and agents walking at each other turn aside from further away than plain ORCA lets
// them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <random>
#include <vector>

#include "msim/crowd/lookahead/agent_lookahead.hpp"
#include "msim/crowd/lookahead/discrete_lookahead.hpp"
#include "msim/crowd/orca.hpp"

namespace {

using namespace msim::crowd;

Agents orcaAgents(const std::vector<Vec2f>& starts, float radius) {
  Agents a;
  for (const Vec2f& x : starts) {
    AgentSpec s;
    s.position = x;
    s.radius = radius;
    s.maxSpeed = 1.4f;
    s.model = AgentModel::Orca;
    a.add(s);
  }
  return a;
}

// Steps the agents towards their goals with ORCA, with the lookahead when `ahead` is given (its
// settings' discreteSolve: the far levels in ORCA's program, or their answer, asked every step, as
// ORCA's preferred velocity); calls observe(step, agents) after each step.
template <typename Observe>
void walk(Agents& a, const std::vector<Vec2f>& goals, int steps, float dt, lookahead::AgentLookahead* ahead,
          Observe&& observe) {
  OrcaParams params;
  params.maxNeighbours = 1000;  // the seed removes RVO2's cap, so that every agent within R counts
  OrcaSolver solver;
  const StaticObstacles none;
  std::vector<Vec2f> v(a.size());
  for (int s = 0; s < steps; ++s) {
    for (std::size_t i = 0; i < a.size(); ++i) {
      const Vec2f d = goals[i] - a.position[i];
      const float len = d.norm();
      a.preferredVelocity[i] = len > 1e-6f ? Vec2f(d * std::min(a.maxSpeed[i], len / dt) / len) : Vec2f::Zero();
    }
    const lookahead::DiscreteLookahead* la =
        ahead ? &ahead->prepare(a, none, params.neighbourDist, 1.4, msim::Vec2::Zero(), msim::Vec2::Zero(), {.tree = true}) : nullptr;
    if (la && ahead->settings().discreteSolve == lookahead::DiscreteSolve::Cascade) {
      std::vector<HalfPlane> planes, scratch;
      std::vector<Vec2f> far(a.size());
      for (std::size_t i = 0; i < a.size(); ++i)
        far[i] = lookahead::farLevelsVelocity(*la, static_cast<std::uint32_t>(i), a.position[i], a.velocity[i], a.radius[i],
                                              1.0f / params.timeHorizon, a.preferredVelocity[i], a.maxSpeed[i], planes, scratch);
      a.preferredVelocity = far;
      la = nullptr;
    }
    solver.computeVelocities(a, none, params, dt, v, la);
    std::vector<Vec2f> previous = a.velocity;
    for (std::size_t i = 0; i < a.size(); ++i) {
      a.velocity[i] = v[i];
      a.position[i] += dt * v[i];
    }
    if (ahead) ahead->record(previous, a.velocity, dt);
    observe(s, a);
  }
}

}  // namespace

TEST(DiscreteLookahead, KeepsOrcasLevelZeroGuaranteeInDenseRandomCrowds) {
  // L2: 80 agents of radius 0.25 m at random in a 12 x 12 m square walk to random goals in it for
  // 10 s. The seed expects no two closer than r_i + r_j - 1 mm with and without the lookahead; this
  // ORCA (float positions, the least-penetration program where the half-planes leave no velocity)
  // lets pairs overlap by about 1 cm here (float positions and steps make single runs chaotic:
  // either may overlap a little more). None may overlap by more than a tenth of a radius: the
  // single solve's far constraints join level 0's program without loosening it, the cascade's only
  // bend its preferred velocity.
  using lookahead::DiscreteSolve;
  struct Variant {
    const char* name;
    int levels;
    DiscreteSolve solve;
  };
  for (const Variant& variant : {Variant{"plain_orca", 0, DiscreteSolve::Single}, Variant{"single_solve", 8, DiscreteSolve::Single},
                                 Variant{"cascade", 8, DiscreteSolve::Cascade}}) {
    std::mt19937 random(17);
    const std::size_t kAgents = 80;
    std::uniform_real_distribution<float> u(0.0f, 12.0f);
    std::vector<Vec2f> starts, goals;
    while (starts.size() < kAgents) {
      const Vec2f x(u(random), u(random));
      if (std::all_of(starts.begin(), starts.end(), [&](const Vec2f& y) { return (x - y).norm() > 0.55f; }))
        starts.push_back(x);
    }
    for (std::size_t i = 0; i < starts.size(); ++i) goals.emplace_back(u(random), u(random));
    Agents a = orcaAgents(starts, 0.25f);
    lookahead::LookaheadSettings settings;
    settings.levels = variant.levels;
    settings.baseStep = 0.05;
    settings.discreteSolve = variant.solve;
    lookahead::AgentLookahead ahead(settings);
    float closest = 1e9f;
    walk(a, goals, 200, 0.05f, variant.levels > 0 ? &ahead : nullptr, [&](int, const Agents& agents) {
      for (std::size_t i = 0; i < agents.size(); ++i)
        for (std::size_t j = i + 1; j < agents.size(); ++j)
          closest = std::min(closest, (agents.position[i] - agents.position[j]).norm() - agents.radius[i] - agents.radius[j]);
    });
    testing::Test::RecordProperty(std::string(variant.name) + "_overlap_m", std::to_string(-closest));
    EXPECT_GE(closest, -0.025f) << variant.name;
  }
}

TEST(DiscreteLookahead, AgentsWalkingAtEachOtherTurnAsideFromFurtherAway) {
  // Two agents 20 m apart walk at each other at 1.4 m/s, 0.1 m off the same line. Plain ORCA (R = 3 m,
  // tau = 2 s) sees the other only within R; with 8 levels of 0.05 s (horizons to 6.4 s, bands to
  // R + 2 v_max 6.4 s) the lookahead sees it from the start and the agents turn aside while still
  // far apart, whether the far levels sit in level 0's program or bend its preferred velocity.
  const auto turnDistance = [](lookahead::AgentLookahead* ahead) {
    Agents a = orcaAgents({Vec2f(0.0f, 0.05f), Vec2f(20.0f, -0.05f)}, 0.25f);
    a.velocity[0] = Vec2f(1.4f, 0.0f);
    a.velocity[1] = Vec2f(-1.4f, 0.0f);
    float distance = 0.0f;
    walk(a, {Vec2f(40.0f, 0.05f), Vec2f(-20.0f, -0.05f)}, 200, 0.05f, ahead, [&](int, const Agents& agents) {
      if (distance == 0.0f && std::abs(agents.velocity[0].y()) > 0.05f)
        distance = (agents.position[1] - agents.position[0]).norm();
    });
    return distance;
  };
  const float plain = turnDistance(nullptr);
  EXPECT_GT(plain, 0.0f);
  EXPECT_LT(plain, 7.0f) << "plain ORCA reacts within its horizon";
  testing::Test::RecordProperty("plain_turn_distance_m", std::to_string(plain));
  for (const auto solve : {lookahead::DiscreteSolve::Single, lookahead::DiscreteSolve::Cascade}) {
    lookahead::LookaheadSettings settings;
    settings.levels = 8;
    settings.baseStep = 0.05;
    settings.discreteSolve = solve;
    lookahead::AgentLookahead ahead(settings);
    const float early = turnDistance(&ahead);
    const std::string name = solve == lookahead::DiscreteSolve::Single ? "single_solve" : "cascade";
    testing::Test::RecordProperty(name + "_turn_distance_m", std::to_string(early));
    EXPECT_GT(early, 1.5f * plain) << name << ": plain " << plain << " m";
  }
}

// One traversal serving a batch of agents gives each the constraints, in the order, that a
// traversal of its own gives it: agents of a crowd with crossing streams (so clusters open), each
// at its own depth (0: none), in batches of neighbours and of agents far apart.
TEST(DiscreteLookahead, ABatchTraversalGivesEachAgentItsOwnConstraints) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> at(0.0f, 30.0f), heading(0.0f, 6.2831853f);
  std::vector<Vec2f> starts;
  for (int i = 0; i < 600; ++i) starts.emplace_back(at(rng), at(rng));
  Agents a = orcaAgents(starts, 0.25f);
  std::vector<std::uint8_t> depth(a.size());
  for (std::size_t i = 0; i < a.size(); ++i) {
    const float h = heading(rng);
    a.velocity[i] = Vec2f(std::cos(h), std::sin(h)) * (i % 2 == 0 ? 1.3f : 0.4f);  // two speeds: not all alike
    depth[i] = static_cast<std::uint8_t>(i % 9);
  }
  lookahead::DiscreteLookahead la;
  la.schedule = lookahead::HorizonSchedule{0.05, 8, 2.0, 3.0, 1.4};
  la.tabulate();
  la.tree.build(a.position, a.velocity, a.radius);
  la.positions = a.position;
  la.velocities = a.velocity;
  la.radii = a.radius;
  la.depth = depth;
  const float invTau = 0.5f;
  const auto alone = [&](std::uint32_t i) {
    std::vector<HalfPlane> planes;
    const lookahead::LookaheadAgent agent{i, a.position[i], a.velocity[i], a.radius[i]};
    lookahead::appendLookaheadPlanes(la, std::span(&agent, 1), invTau, std::span(&planes, 1));
    return planes;
  };
  // Neighbours: the tree's order keeps agents near each other together; strangers: every 75th.
  const std::span<const std::uint32_t> treeOrder = la.tree.agents();
  std::vector<std::vector<std::uint32_t>> batches;
  for (std::size_t b = 0; b + lookahead::kLookaheadBatch <= treeOrder.size(); b += 40)
    batches.emplace_back(treeOrder.begin() + static_cast<std::ptrdiff_t>(b),
                         treeOrder.begin() + static_cast<std::ptrdiff_t>(b + lookahead::kLookaheadBatch));
  for (std::uint32_t b = 0; b < 5; ++b) {
    batches.emplace_back();
    for (std::uint32_t k = 0; k < lookahead::kLookaheadBatch; ++k) batches.back().push_back(b + 75 * k);
  }
  std::size_t compared = 0, planesSeen = 0;
  for (const std::vector<std::uint32_t>& members : batches) {
    std::vector<lookahead::LookaheadAgent> batch;
    for (const std::uint32_t i : members) batch.push_back({i, a.position[i], a.velocity[i], a.radius[i]});
    std::vector<std::vector<HalfPlane>> planes(batch.size());
    lookahead::appendLookaheadPlanes(la, batch, invTau, planes);
    for (std::size_t k = 0; k < batch.size(); ++k) {
      const std::vector<HalfPlane> own = alone(members[k]);
      ASSERT_EQ(planes[k].size(), own.size()) << "agent " << members[k];
      if (depth[members[k]] == 0) {
        EXPECT_TRUE(own.empty());
      }
      for (std::size_t p = 0; p < own.size(); ++p) {
        EXPECT_EQ(planes[k][p].point, own[p].point) << "agent " << members[k] << ", constraint " << p;
        EXPECT_EQ(planes[k][p].normal, own[p].normal) << "agent " << members[k] << ", constraint " << p;
      }
      ++compared;
      planesSeen += own.size();
    }
  }
  EXPECT_GT(compared, 100u);
  EXPECT_GT(planesSeen, 20 * compared);  // far levels that hold agents and clusters
}
