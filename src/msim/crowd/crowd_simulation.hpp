#pragma once
// The crowd time step of Narain 2011 ch. 4.4.4, with the agent kinds of ch. 4.4.3 mixed in one
// scene:
//   1. global planning: preferred velocities v~_i from the planner (cached fields or roadmap);
//   2. individually controlled agents first: scripted agents follow their waypoints, ORCA agents
//      avoid everybody by ORCA; both then count as moving obstacles of the continuum;
//   3. free-area fractions f of the grid (static obstacles precomputed, moving ones per step);
//   4. the UIC projection v = psolve(renorm(psolve(v~))) (eq. 4.20) and agent velocities (4.3);
//   5. x_i += v_i dt;
//   6. pairwise collision resolution, out of obstacles, inside the domain;
//   7. arrivals (agents at an exit goal leave) and inflows (agents/s into spawn regions).
// Each part can be switched off (uic, collision resolution) to reproduce Fig. 4.3.
#include <limits>
#include <memory>
#include <optional>
#include <vector>

#include "msim/core/parallel.hpp"
#include "msim/core/rng.hpp"
#include "msim/core/timer.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/collision_resolution.hpp"
#include "msim/crowd/free_area.hpp"
#include "msim/crowd/goal.hpp"
#include "msim/crowd/lookahead/agent_lookahead.hpp"
#include "msim/crowd/orca.hpp"
#include "msim/crowd/planner.hpp"
#include "msim/crowd/speed_distribution.hpp"
#include "msim/crowd/stress/stress_dynamics.hpp"
#include "msim/crowd/uic_projection.hpp"
#include "msim/crowd/walking_density.hpp"

namespace msim::crowd {

// Agents entering through a region at a steady rate (the four-way crossing of Fig. 4.6).
struct Inflow {
  Polygon region;
  double rate = 1.0;  // [agents/s]; 0 only for a recycling inflow
  // Besides its rate, the inflow re-admits agents that leave through exits (each leaver by one of
  // the recycling inflows open at the time, chosen by its id), so a crowd keeps its count: the
  // fixed-density runs of Golas ch. 4's Hajj sweep.
  bool recycle = false;
  double start = 0.0, stop = std::numeric_limits<double>::infinity();  // [s]
  AgentSpec agent;    // goal, radius, speed, model, group of the new agents (position ignored)
  SpeedDistribution speeds;  // each new agent's speed, unless Fixed (then agent.maxSpeed)
};

// A scripted agent walks its waypoints in order at its maximum speed and then stands (or loops).
struct Script {
  std::uint64_t agentId = 0;
  std::vector<Vec2> waypoints;
  bool loop = false;
};

// A polygon in rigid translation, x(t) = x(0) + v t + A sin(2 pi f t) for every vertex (the
// motion of the smoke phenomenon's obstacles): vehicles, sliding doors, a swinging barrier. The
// continuum sees it through the free area of the cells it covers, recomputed every step (ch. 4.4.3
// step 4); collision resolution and ORCA keep agents out of it; global planning ignores it.
struct MovingObstacle {
  Polygon shape;  // at t = 0
  Vec2 velocity = Vec2::Zero();   // [m/s]
  Vec2 amplitude = Vec2::Zero();  // [m]
  double frequency = 0.0;         // [1/s]
  Polygon at(double t) const;
};

struct CrowdSettings {
  Vec2 lo = Vec2::Zero(), hi = Vec2::Ones();  // walkable box; its sides are walls [m]
  GridSpec<2> grid;                           // the continuum grid of the UIC
  bool uic = true;                            // off: agents walk their preferred velocity (Fig. 4.3b)
  UicSettings uicSettings;
  // The UIC agents' walking speed falls with the density ahead along Weidmann's fundamental
  // diagram (walking_density.hpp); disabled: the seed's constant v_max.
  SpeedDensitySettings speedDensity;
  bool collisionResolution = true;            // off: Fig. 4.3c
  CollisionResolutionParams collision;
  OrcaParams orca;
  lookahead::LookaheadSettings lookahead;     // long-range avoidance (Golas ch. 3)
  // Inter-personal stress (Golas ch. 4): when set, the UIC agents move by eqs. 4.6-4.7 towards the
  // continuum navigation's collision-free velocity instead of by the UIC projection.
  std::optional<stress::StressSettings> stress;
  std::uint64_t seed = 1;                     // inflow positions (one stream per new agent id)
};

// The continuum lookahead's work in a step: eq. 3.2's solves (agents x levels) and their
// gradient-ascent iterations; the hybrid's ORCA agents and their mean blend weight w (eq. 3.11).
struct LookaheadStepStats {
  std::size_t solves = 0, iterations = 0, blended = 0;
  double meanWeight = 0.0;
};

struct CrowdStepStats {
  std::size_t agents = 0, uicAgents = 0, orcaAgents = 0, scriptedAgents = 0;
  std::size_t spawned = 0, exited = 0;  // this step
  UicStats uic;                         // the last projection (zeros when off or no UIC agents)
  stress::StressStepStats stress;       // the stress model's solves (zeros without it)
  LookaheadStepStats lookahead;         // zeros without continuum lookahead
};

// An agent that left through an exit: the evacuation-time metrics read these.
struct ExitEvent {
  std::uint64_t agentId = 0;
  std::uint32_t goal = 0;
  double time = 0.0;  // [s]
};

class CrowdSimulation {
 public:
  // `planner` answers for `goals` (same indices). Throws InputError naming the object for an
  // agent outside the domain or inside an obstacle, a goal index out of range, an unreachable
  // goal, a script for an unknown or non-scripted agent, or an inflow region outside the domain.
  CrowdSimulation(const CrowdSettings& settings, std::vector<Polygon> obstacles, std::vector<Goal> goals,
                  std::shared_ptr<const GlobalPlanner> planner, Agents agents, std::vector<Inflow> inflows = {},
                  std::vector<Script> scripts = {}, std::vector<MovingObstacle> moving = {});

  void step(double dt, StageTimers* timers = nullptr);

  const Agents& agents() const { return agents_; }
  Agents& mutableAgents() { return agents_; }  // for restoring a saved state
  double time() const { return time_; }
  void setTime(double t) { time_ = t; }
  const CrowdSettings& settings() const { return settings_; }
  const std::vector<Polygon>& obstacles() const { return obstacles_; }
  // The moving obstacles where they are at time() (after the last step).
  std::vector<Polygon> movingObstaclesNow() const;
  const std::vector<Goal>& goals() const { return goals_; }
  const CrowdStepStats& lastStep() const { return stats_; }
  // The inconsistency metric (Golas ch. 3.8): per agent (localInconsistency) and the scene's.
  const lookahead::AgentLookahead& lookahead() const { return lookahead_; }
  const UicProjection& uic() const { return uic_; }
  // The stress model's fields (density, velocity, stress) of its last evaluation; null without it.
  const stress::StressDynamics* stress() const { return stress_ ? &*stress_ : nullptr; }
  const FreeArea& freeArea() const { return freeArea_; }
  // Exits since the start (kept for the whole run).
  const std::vector<ExitEvent>& exits() const { return exits_; }
  // Inflow bookkeeping, for restoring a saved state: agents owed to each inflow (fractional).
  std::vector<double>& inflowCredit() { return inflowCredit_; }
  const std::vector<double>& inflowCredit() const { return inflowCredit_; }
  // Next waypoint of each script, for saving and restoring a run.
  std::vector<std::size_t>& scriptProgress() { return scriptProgress_; }
  const std::vector<std::size_t>& scriptProgress() const { return scriptProgress_; }
  const std::vector<Script>& scripts() const { return scripts_; }
  // The fastest an agent may walk [m/s] (for CFL-like time step limits).
  double maxSpeed() const;

  // Agents that want to walk (preferred speed at least half their maximum; scripted ones aside)
  // and have free space ahead (fewer than kFreeDensity others per m^2 in the square ahead,
  // walking_density.hpp): their number and mean speed. A crowd whose free walkers stand still has
  // stalled, whatever the cause (a continuum that cannot work on its grid, a deadlock).
  static constexpr double kFreeDensity = 1.0;
  struct FreeWalkers {
    std::size_t count = 0;
    double meanSpeed = 0.0;  // [m/s]
  };
  FreeWalkers freeWalkers();

 private:
  void validateAgent(std::size_t i, const std::string& what) const;
  // Index of the agent with this id, size() if it has left.
  std::size_t indexOfId(std::uint64_t id) const;
  void plan();
  void moveScripted(double dt);
  // Depths, the agent tree and the future densities; the continuum lookahead's velocities (UIC
  // agents: their preferred velocity) and the hybrid's weights.
  void prepareLookahead(double dt);
  void refreshDiscreteFarLevels();
  void applyFarSuggestions(bool uic);
  void moveOrca(double dt);
  void walkingSpeeds();
  // The UIC agents' indices into uicIndex_ and the other agents as discs of the continuum.
  void splitContinuumAgents();
  // to[k] = from[uicIndex_[k]] for every UIC agent (in parallel).
  template <typename T>
  void gatherContinuum(std::span<const T> from, std::vector<T>& to) const {
    to.resize(uicIndex_.size());
    parallelFor(0, uicIndex_.size(), [&](std::size_t k) { to[k] = from[uicIndex_[k]]; });
  }
  void moveUic(double dt);
  void moveStressed(double dt);
  void arriveAndSpawn(double dt);
  Vec2f streamVelocity(const Polygon& region, std::uint32_t goal) const;
  // Static and moving obstacles at time t, indexed for the local passes (only rebuilt when some move).
  void placeMovingObstacles(double t);
  const StaticObstacles& obstacleIndex() const { return moving_.empty() ? staticObstacles_ : allObstacles_; }

  CrowdSettings settings_;
  std::vector<Polygon> obstacles_;
  std::vector<Goal> goals_;
  // What plan() reads of each goal, 32 bytes instead of a Goal's 64 (the circle scene has a goal
  // per agent, so planning streams these; 100k Goals would crowd the agents out of the cache): the
  // point and the squared arrival radius, in double precision as Goal::reached tests them (an agent
  // that plan() stops must count as arrived), the kind.
  struct GoalSummary {
    Vec2 point;
    double arrival2;
    bool isPoint, exit;
  };
  std::vector<GoalSummary> goalSummaries_;
  bool anyExitGoal_ = false;
  std::shared_ptr<const GlobalPlanner> planner_;
  Agents agents_;
  std::vector<Inflow> inflows_;
  std::vector<double> inflowCredit_;
  std::vector<std::size_t> recycling_;  // scratch: the recycling inflows open now
  std::vector<Script> scripts_;
  std::vector<std::size_t> scriptProgress_;  // next waypoint per script
  double time_ = 0.0;
  Rng rng_;

  StaticObstacles staticObstacles_;
  std::vector<MovingObstacle> moving_;
  std::vector<Polygon> movingNow_, allNow_;  // this step's moving polygons; static + moving
  StaticObstacles allObstacles_;
  float obstacleReach_ = 0.0f;
  FreeArea freeArea_;
  UicProjection uic_;
  std::optional<WalkingDensity> walkingDensity_;  // speeds when speedDensity.enabled; freeWalkers()
  OrcaSolver orca_;
  lookahead::AgentLookahead lookahead_;   // and the inconsistency metric of every agent
  std::optional<stress::StressDynamics> stress_;
  const lookahead::DiscreteLookahead* ahead_ = nullptr;  // this step's, from prepareLookahead()
  std::vector<Vec2f> farDirection_;  // per agent: the continuum lookahead's far levels' direction (0: none)
  // Per agent: the discrete cascade's far levels' velocity per unit of preferred speed, where set.
  std::vector<Vec2f> farOrca_;
  std::vector<std::uint8_t> farOrcaSet_;
  struct FarScratch {
    std::vector<HalfPlane> planes, projected;
  };
  tbb::enumerable_thread_specific<FarScratch> farScratch_;
  double sinceRefresh_ = 0.0;        // [s] since the far levels were last asked
  bool refreshed_ = false;
  std::vector<Vec2f> stepStartVelocity_;
  CollisionResolver resolver_;
  CrowdStepStats stats_;
  std::vector<ExitEvent> exits_;

  // Per-step scratch, kept to avoid allocation.
  std::vector<Vec2f> orcaVelocity_, continuumVelocity_, discCentres_, uicPosition_, uicPreferred_, uicVelocity_;
  std::vector<float> discRadii_, uicSpeed_, walkDensity_, walkSpeed_, blendWeight_;
  std::vector<std::uint8_t> skipOrca_;
  std::vector<int> continuumIterations_, continuumSolves_;
  std::vector<std::uint32_t> uicIndex_;
  std::vector<std::uint8_t> remove_;
};

}  // namespace msim::crowd
