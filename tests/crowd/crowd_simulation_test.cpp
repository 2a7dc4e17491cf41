// The crowd time step of ch. 4.4.4 as a whole: the density cap of the UIC after every projection
// with obstacles (ch. 4.4.3), inflow rates and exits, scripted agents that walk their script and are
// obstacles to the others, and UIC and ORCA agents sharing a scene (Fig. 4.4) without overlaps.
#include "msim/crowd/crowd_simulation.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/core/error.hpp"
#include "msim/core/rng.hpp"
#include "msim/crowd/direct_planner.hpp"
#include "msim/crowd/metrics.hpp"
#include "msim/crowd/navigation_field.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

constexpr float kRadius = 0.25f;

CrowdSettings settings(const Vec2& hi, int resolutionX, const Vec2& lo = Vec2::Zero()) {
  CrowdSettings s;
  s.lo = lo;
  s.hi = hi;
  const double dx = (hi.x() - lo.x()) / resolutionX;
  s.grid = GridSpec<2>(lo, dx, IVec2(resolutionX, static_cast<int>(std::lround((hi.y() - lo.y()) / dx))));
  s.uicSettings.rhoMax = 0.64 * 2.0 / (std::sqrt(3.0) * 4 * kRadius * kRadius);  // eq. 4.4, alpha 0.64
  s.collision.separation = 1.2f;
  s.collision.iterations = 12;
  s.speedDensity.enabled = false;  // the seed's constant v_max; the CLI tests run the default model
  return s;
}

// The exit at the east end of a 30 x 10 m hall.
Goal eastExit() {
  Goal east;
  east.kind = Goal::Kind::Region;
  east.regions = {rectangle(Vec2(28, 0), Vec2(30, 10))};
  east.exit = true;
  return east;
}

// An inflow of agents bound for goal 0 into `region` at `rate` agents/s from `start` to `stop`.
Inflow inflowInto(const Polygon& region, double rate, double start, double stop) {
  Inflow in;
  in.region = region;
  in.rate = rate;
  in.start = start;
  in.stop = stop;
  in.agent.goal = 0;
  in.agent.radius = kRadius;
  return in;
}

// Agents uniformly at random in [lo, hi] (relaxed apart by the simulation's constructor).
Agents randomAgents(std::size_t n, const Vec2& lo, const Vec2& hi, std::uint32_t goal, AgentModel model,
                    std::uint64_t seed) {
  Rng rng(seed);
  Agents a;
  for (std::size_t i = 0; i < n; ++i) {
    AgentSpec s;
    s.position = Vec2f(float(rng.uniform(lo.x(), hi.x())), float(rng.uniform(lo.y(), hi.y())));
    s.radius = kRadius;
    s.goal = goal;
    s.model = model;
    a.add(s);
  }
  return a;
}

double closestPairRatio(const Agents& a) {
  const NearestNeighbours nn = nearestNeighbours(a.position, a.radius, 4 * kRadius);
  double worst = std::numeric_limits<double>::infinity();
  for (double r : nn.ratio) worst = std::min(worst, r);
  return worst;
}

}  // namespace

TEST(CrowdSimulation, DensityStaysCappedAtTheFreeAreaLimitEveryStep) {
  // A room whose right wall has a 1.2 m door (Fig. 4.3): 400 agents press towards an exit behind
  // it. Obstacles cover parts of cells, so the cap f rho_max varies along the wall (ch. 4.4.3).
  const Vec2 hi(20, 20);
  std::vector<Polygon> walls = {rectangle(Vec2(15, 0), Vec2(15.5, 9.4)), rectangle(Vec2(15, 10.6), Vec2(15.5, 20))};
  Goal exit;
  exit.kind = Goal::Kind::Region;
  exit.regions = {rectangle(Vec2(17, 7), Vec2(20, 13))};
  exit.exit = true;
  NavigationFieldOptions nav;
  nav.hi = hi;
  auto planner = std::make_shared<NavigationField>(std::vector<Goal>{exit}, walls, nav);
  CrowdSimulation sim(settings(hi, 20), walls, {exit}, planner, randomAgents(400, Vec2(1, 1), Vec2(14, 19), 0, AgentModel::Uic, 7));
  double worstPredicted = 0.0, worstActual = 0.0, worstOpen = 0.0, worstCut = 0.0;
  int activeSteps = 0;
  for (int step = 0; step < 200; ++step) {
    sim.step(0.1);
    const UicStats& u = sim.lastStep().uic;
    worstPredicted = std::max(worstPredicted, u.maxRatioAfter);
    if (step > 0) worstActual = std::max(worstActual, u.maxRatioBefore);
    {
      const auto& rho = sim.uic().density();
      const auto& f = sim.uic().freeArea();
      for (std::size_t c = 0; c < rho.count(); ++c) {
        const double r = rho[c] / (f[c] * sim.settings().uicSettings.rhoMax);
        if (f[c] >= 0.999) worstOpen = std::max(worstOpen, r);
        else if (f[c] > 0) worstCut = std::max(worstCut, r);
      }
    }
    if (u.activeCells > 0) ++activeSteps;
    ASSERT_LE(u.maxRatioAfter, 1.05) << "step " << step;
  }
  std::printf("doorway: max predicted rho / (f rho_max) after projection %.4f, max splatted before the next %.4f, "
              "UIC active in %d of 200 steps, %zu agents left, %zu exited\n",
              worstPredicted, worstActual, activeSteps, sim.agents().size(), sim.exits().size());
  std::printf("open cells %.3f, cut cells %.3f\n", worstOpen, worstCut);
  EXPECT_GT(activeSteps, 100);        // the queue at the door is at rho_max most of the time
  EXPECT_GT(sim.exits().size(), 50u);  // and it drains through the door
  EXPECT_EQ(sim.exits().size() + sim.agents().size(), 400u);
  EXPECT_GT(closestPairRatio(sim.agents()), 0.9);
}

TEST(CrowdSimulation, InflowAgentsJoinTheStreamInTheirRegion) {
  // A stream of 150 agents walks east through the inflow's region against 40 walking west; the
  // agents the inflow admits from t = 1 s (walking east) start with the mean velocity of the
  // eastbound agents in the region, not at rest and not with the counter-flow's.
  const Vec2 hi(30, 10);
  const Goal east = eastExit();
  Goal west = east;
  west.regions = {rectangle(Vec2(0, 0), Vec2(2, 10))};
  const Inflow in = inflowInto(rectangle(Vec2(3, 0.5), Vec2(10, 9.5)), 4.0, 1.0, 3.0);
  Agents crowd = randomAgents(150, Vec2(3, 0.5), Vec2(10, 9.5), 0, AgentModel::Uic, 5);
  const Agents counterFlow = randomAgents(40, Vec2(8, 0.5), Vec2(14, 9.5), 1, AgentModel::Uic, 6);
  for (std::size_t i = 0; i < counterFlow.size(); ++i) crowd.add(counterFlow.spec(i));
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{east, west});
  CrowdSimulation sim(settings(hi, 30), {}, {east, west}, planner, crowd, {in});
  std::size_t checked = 0, againstSeen = 0;
  for (int step = 0; step < 60; ++step) {
    sim.step(0.05);
    const std::size_t spawned = sim.lastStep().spawned;
    if (spawned == 0) continue;
    const Agents& a = sim.agents();
    const std::size_t first = a.size() - spawned;  // the new agents are the last ones
    Vec2f sum = Vec2f::Zero();
    std::size_t inRegion = 0;
    for (std::size_t i = 0; i < first; ++i) {
      if (!contains(in.region, a.position[i].cast<double>())) continue;
      if (a.goal[i] != 0) {
        againstSeen += a.velocity[i].x() < 0.0f;
        continue;
      }
      sum += a.velocity[i];
      ++inRegion;
    }
    ASSERT_GT(inRegion, 0u);
    const Vec2f stream = sum / float(inRegion);
    ASSERT_GT(stream.x(), 0.3f) << "t = " << sim.time();  // the stream walks east
    for (std::size_t i = first; i < a.size(); ++i) {
      EXPECT_NEAR(a.velocity[i].x(), stream.x(), 1e-5f);
      EXPECT_NEAR(a.velocity[i].y(), stream.y(), 1e-5f);
      ++checked;
    }
  }
  EXPECT_EQ(checked, 8u);
  EXPECT_GT(againstSeen, 0u);  // the counter-flow walked through the region meanwhile
}

TEST(CrowdSimulation, InflowsSpawnAtTheirRateAndExitsRemoveAgents) {
  const Vec2 hi(30, 10);
  const Goal east = eastExit();
  const Inflow in = inflowInto(rectangle(Vec2(0.5, 0.5), Vec2(2, 9.5)), 7.0, 1.0, 11.0);
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{east});
  CrowdSimulation sim(settings(hi, 30), {}, {east}, planner, Agents{}, {in});
  std::size_t spawned = 0;
  for (int step = 0; step < 800; ++step) {
    sim.step(0.05);
    spawned += sim.lastStep().spawned;
    // 7 agents/s from t = 1 s: exactly floor(7 (t - 1)) so far (credit carried between steps).
    const double t = sim.time();
    const std::size_t expected = static_cast<std::size_t>(std::floor(7.0 * std::clamp(t - 1.0, 0.0, 10.0) + 1e-6));
    ASSERT_EQ(spawned, expected) << "t = " << t;
  }
  EXPECT_EQ(spawned, 70u);
  // At 1.4 m/s the walk of at most 27.5 m takes under 20 s: the last agent (t = 11 s) is out by 40 s.
  EXPECT_EQ(sim.agents().size(), 0u);
  ASSERT_EQ(sim.exits().size(), 70u);
  for (std::size_t k = 1; k < sim.exits().size(); ++k) EXPECT_GE(sim.exits()[k].time, sim.exits()[k - 1].time);
  EXPECT_GT(sim.exits().front().time, 1.0 + 26.0 / 1.4 - 2.0);
}

TEST(CrowdSimulation, RecyclingInflowsHoldTheCrowdsCount) {
  // Two recycling inflows (rate 0) at the west end re-admit the agents that leave through the east
  // exit, shared between them: the count stays at the start's after every step while agents
  // leave, and every leaver comes back.
  const Vec2 hi(30, 10);
  const Goal east = eastExit();
  std::vector<Inflow> inflows(2);
  for (std::size_t k = 0; k < 2; ++k) {
    inflows[k].region = rectangle(Vec2(0.5, 0.5 + 5.0 * k), Vec2(2, 4.5 + 5.0 * k));
    inflows[k].rate = 0.0;
    inflows[k].recycle = true;
    inflows[k].agent.goal = 0;
    inflows[k].agent.radius = kRadius;
  }
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{east});
  const std::size_t start = 120;
  CrowdSimulation sim(settings(hi, 30), {}, {east}, planner, randomAgents(start, Vec2(3, 1), Vec2(27, 9), 0, AgentModel::Uic, 5),
                      inflows);
  std::size_t spawned = 0;
  for (int step = 0; step < 600; ++step) {
    sim.step(0.05);
    spawned += sim.lastStep().spawned;
    ASSERT_EQ(sim.agents().size(), start) << "t = " << sim.time();
  }
  EXPECT_GT(sim.exits().size(), start);  // more than the whole crowd has passed the exit
  EXPECT_EQ(spawned, sim.exits().size());
  // The other inflow's agents and an inflow that neither recycles nor has a rate: refused.
  inflows[0].recycle = false;
  EXPECT_THROW(CrowdSimulation(settings(hi, 30), {}, {east}, planner, Agents{}, inflows), InputError);
}

TEST(CrowdSimulation, ScriptedAgentsWalkTheirScriptAndOthersGiveWay) {
  // A scripted agent crosses a crowd walking the other way (ch. 4.4.3): it keeps its path and
  // speed exactly, and nobody overlaps it.
  const Vec2 hi(30, 30);
  Goal west;
  west.point = Vec2(2, 15);
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{west});
  Agents agents = randomAgents(300, Vec2(12, 10), Vec2(24, 20), 0, AgentModel::Uic, 11);
  AgentSpec walker;
  walker.position = Vec2f(4, 15);
  walker.radius = 0.4f;
  walker.maxSpeed = 1.0f;
  walker.model = AgentModel::Scripted;
  const std::size_t w = agents.add(walker);
  const std::uint64_t id = agents.id[w];
  Script script{id, {Vec2(26, 15), Vec2(26, 25)}, false};
  CrowdSimulation sim(settings(hi, 30), {}, {west}, planner, std::move(agents), {}, {script});
  double closest = std::numeric_limits<double>::infinity();
  for (int step = 1; step <= 250; ++step) {
    sim.step(0.1);
    const Agents& a = sim.agents();
    const std::size_t k = std::find(a.id.begin(), a.id.end(), id) - a.id.begin();
    const Vec2 x = a.position[k].cast<double>();
    // Arc length 1 m/s x t along the script: 22 m east, then north.
    const double s = std::min(0.1 * step, 32.0);
    const Vec2 expected = s <= 22.0 ? Vec2(4 + s, 15) : Vec2(26, 15 + (s - 22.0));
    ASSERT_NEAR((x - expected).norm(), 0.0, 1e-4) << "step " << step;
    for (std::size_t j = 0; j < a.size(); ++j)
      if (j != k) closest = std::min(closest, (a.position[j] - a.position[k]).norm() / double(a.radius[j] + a.radius[k]));
  }
  std::printf("scripted walker: closest approach %.3f d_min\n", closest);
  EXPECT_GT(closest, 0.95);
}

TEST(CrowdSimulation, MovingObstaclePushesThroughTheCrowd) {
  // A 2 m box drives at 1 m/s through a standing crowd (ch. 4.4.3: moving obstacles change the
  // free area every step): nobody ends a step inside it or closer than a radius, and the
  // continuum's density cap follows it.
  const Vec2 hi(24, 20);
  Goal stay;
  stay.point = Vec2(12, 10);
  stay.arrivalRadius = 8.0;  // everybody is already there: they only make room
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{stay});
  MovingObstacle car;
  car.shape = rectangle(Vec2(0.5, 9), Vec2(2.5, 11));
  car.velocity = Vec2(1.0, 0.0);
  CrowdSimulation sim(settings(hi, 24), {}, {stay}, planner, randomAgents(600, Vec2(4, 4), Vec2(20, 16), 0, AgentModel::Uic, 13),
                      {}, {}, {car});
  double worstClearance = std::numeric_limits<double>::infinity(), worstPredicted = 0.0;
  for (int step = 0; step < 180; ++step) {
    sim.step(0.1);
    const Polygon now = sim.movingObstaclesNow().at(0);
    for (const Vec2f& x : sim.agents().position)
      worstClearance = std::min(worstClearance, signedDistance(now, x.cast<double>()) - kRadius);
    // Cells the box covers (f < 1) may hold agents it has not pushed out yet, which no flow
    // can fix within the step; the cap is checked on the open cells.
    const auto& predicted = sim.uic().predictedDensity();
    const auto& f = sim.uic().freeArea();
    for (std::size_t c = 0; c < predicted.count(); ++c)
      if (f[c] >= 0.999f) worstPredicted = std::max(worstPredicted, predicted[c] / (f[c] * sim.settings().uicSettings.rhoMax));
  }
  std::printf("moving box through 600 agents: worst clearance %.2e m, predicted density in open cells %.4f f rho_max\n",
              worstClearance, worstPredicted);
  EXPECT_GT(worstClearance, -1e-3);
  EXPECT_LE(worstPredicted, 1.05);
  EXPECT_NEAR(sim.movingObstaclesNow().at(0).vertices[0].x(), 0.5 + 18.0, 1e-9);
}

TEST(CrowdSimulation, UicAndOrcaAgentsShareAScene) {
  // Fig. 4.4: a UIC group and an ORCA group cross at right angles; neither kind overlaps the other.
  const Vec2 hi(40, 40);
  Goal east, north;
  east.kind = north.kind = Goal::Kind::Region;
  east.regions = {rectangle(Vec2(38, 0), Vec2(40, 40))};
  north.regions = {rectangle(Vec2(0, 38), Vec2(40, 40))};
  east.exit = north.exit = true;
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{east, north});
  Agents agents = randomAgents(200, Vec2(2, 14), Vec2(12, 26), 0, AgentModel::Uic, 3);
  const Agents orca = randomAgents(100, Vec2(15, 2), Vec2(25, 10), 1, AgentModel::Orca, 4);
  for (std::size_t i = 0; i < orca.size(); ++i) agents.add(orca.spec(i));
  CrowdSimulation sim(settings(hi, 40), {}, {east, north}, planner, std::move(agents));
  double worstMixed = std::numeric_limits<double>::infinity();
  for (int step = 0; step < 400; ++step) {
    sim.step(0.1);
    const Agents& a = sim.agents();
    const NearestNeighbours nn = nearestNeighbours(a.position, a.radius, 4 * kRadius);
    for (double r : nn.ratio) worstMixed = std::min(worstMixed, r);
  }
  std::printf("UIC + ORCA crossing: closest pair %.3f d_min over 40 s, %zu of 300 agents arrived\n", worstMixed,
              sim.exits().size());
  EXPECT_GT(worstMixed, 0.9);
  EXPECT_GT(sim.exits().size(), 250u);
}

TEST(CrowdSimulation, RefusesAgentsOutsideTheDomainOrWithUnreachableGoals) {
  const Vec2 hi(10, 10);
  Goal g;
  g.point = Vec2(5, 5);
  auto planner = std::make_shared<DirectPlanner>(std::vector<Goal>{g});
  EXPECT_THROW(CrowdSimulation(settings(hi, 10), {}, {g}, planner, randomAgents(3, Vec2(11, 1), Vec2(12, 2), 0, AgentModel::Uic, 1)),
               InputError);
  EXPECT_THROW(CrowdSimulation(settings(hi, 10), {}, {g}, planner, randomAgents(3, Vec2(1, 1), Vec2(2, 2), 5, AgentModel::Uic, 1)),
               InputError);
  // A goal inside a closed ring of walls.
  const std::vector<Polygon> ring = {rectangle(Vec2(3, 3), Vec2(7, 3.5)), rectangle(Vec2(3, 6.5), Vec2(7, 7)),
                                     rectangle(Vec2(3, 3.5), Vec2(3.5, 6.5)), rectangle(Vec2(6.5, 3.5), Vec2(7, 6.5))};
  NavigationFieldOptions nav;
  nav.hi = hi;
  auto field = std::make_shared<NavigationField>(std::vector<Goal>{g}, ring, nav);
  try {
    CrowdSimulation(settings(hi, 10), ring, {g}, field, randomAgents(3, Vec2(0.5, 0.5), Vec2(2, 2), 0, AgentModel::Uic, 1));
    FAIL() << "an enclosed goal must be refused";
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("cannot be reached"), std::string::npos) << e.what();
  }
}

TEST(CrowdSimulation, AnAgentThatStopsAtItsPointGoalHasArrived) {
  // Agents far from the origin (4 km: single precision rounds a point there by up to 2.4e-4 m) walk
  // 2 m each to a goal of their own with a 0.1 m arrival radius, as the circle scene's, and stop
  // there: every agent that planning stops must be one that Goal::reached counts, else the last
  // fraction of a millimetre leaves it standing still short of its goal for good.
  const Vec2 lo(4096, 4096), hi(4516, 4516);
  const CrowdSettings s = settings(hi, 42, lo);
  Rng rng(3);
  std::vector<Goal> goals;
  Agents agents;
  for (int gx = 0; gx < 66; ++gx)
    for (int gy = 0; gy < 66; ++gy) {
      const Vec2 start = lo + Vec2(12.0 + 6.0 * gx + rng.uniform(-0.5, 0.5), 12.0 + 6.0 * gy + rng.uniform(-0.5, 0.5));
      const double heading = rng.uniform(0.0, 6.283185307179586);
      Goal g;
      g.point = start + 2.0 * Vec2(std::cos(heading), std::sin(heading));
      g.arrivalRadius = 0.1;
      AgentSpec spec;
      spec.position = start.cast<float>();
      spec.radius = kRadius;
      spec.model = AgentModel::Orca;
      spec.goal = static_cast<std::uint32_t>(goals.size());
      goals.push_back(g);
      agents.add(spec);
    }
  auto planner = std::make_shared<DirectPlanner>(goals);
  CrowdSimulation sim(s, {}, goals, planner, std::move(agents));
  for (int step = 0; step < 200; ++step) sim.step(0.05);
  std::size_t standing = 0, short_ = 0;
  const Agents& a = sim.agents();
  for (std::size_t i = 0; i < a.size(); ++i) {
    if (a.preferredVelocity[i].norm() > 0.0f) continue;
    ++standing;
    if (!goals[a.goal[i]].reached(a.position[i].cast<double>())) ++short_;
  }
  std::printf("%zu agents: %zu stopped, %zu of them short of their goals\n", a.size(), standing, short_);
  EXPECT_EQ(standing, a.size());  // 10 s: everyone has arrived and stopped
  EXPECT_EQ(short_, 0u);
}
