#include "msim/crowd/crowd_simulation.hpp"

#include <algorithm>
#include <cmath>
#include <span>
#include <utility>

#include <fmt/format.h>
#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/error.hpp"
#include "msim/core/parallel.hpp"
#include "msim/crowd/direct_planner.hpp"

namespace msim::crowd {
namespace {

constexpr int kRelaxSweeps = 50;

// Largest radius and speed over the initial agents and every agent an inflow will create.
void extremes(const Agents& agents, const std::vector<Inflow>& inflows, float& radius, float& speed) {
  // One parallel pass: the time step asks for the fastest agent every step.
  const auto largest = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, agents.size(), 1 << 14), std::pair{0.0f, 0.0f},
      [&](const tbb::blocked_range<std::size_t>& r, std::pair<float, float> m) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          m.first = std::max(m.first, agents.radius[i]);
          m.second = std::max(m.second, agents.maxSpeed[i]);
        }
        return m;
      },
      [](std::pair<float, float> a, const std::pair<float, float>& b) {
        return std::pair{std::max(a.first, b.first), std::max(a.second, b.second)};
      });
  radius = largest.first;
  speed = largest.second;
  for (const Inflow& f : inflows) {
    radius = std::max(radius, f.agent.radius);
    speed = std::max(speed, f.agent.maxSpeed);
  }
}

float obstacleReach(const Agents& agents, const std::vector<Inflow>& inflows, const OrcaParams& orca) {
  float radius = 0.0f, speed = 0.0f;
  extremes(agents, inflows, radius, speed);
  return std::max(radius, speed * orca.timeHorizonObst + radius) + 1e-3f;
}

}  // namespace

CrowdSimulation::CrowdSimulation(const CrowdSettings& settings, std::vector<Polygon> obstacles, std::vector<Goal> goals,
                                 std::shared_ptr<const GlobalPlanner> planner, Agents agents, std::vector<Inflow> inflows,
                                 std::vector<Script> scripts, std::vector<MovingObstacle> moving)
    : settings_(settings),
      obstacles_(std::move(obstacles)),
      goals_(std::move(goals)),
      anyExitGoal_(std::any_of(goals_.begin(), goals_.end(), [](const Goal& g) { return g.exit; })),
      planner_(std::move(planner)),
      agents_(std::move(agents)),
      inflows_(std::move(inflows)),
      inflowCredit_(inflows_.size(), 0.0),
      scripts_(std::move(scripts)),
      scriptProgress_(scripts_.size(), 0),
      rng_(settings.seed),
      staticObstacles_(obstacles_, obstacleReach(agents_, inflows_, settings.orca)),
      moving_(std::move(moving)),
      obstacleReach_(obstacleReach(agents_, inflows_, settings.orca)),
      freeArea_(settings.grid),
      uic_(settings.grid, settings.uicSettings),
      lookahead_(settings.lookahead) {
  if (settings_.stress) stress_.emplace(settings_.grid, *settings_.stress);
  goalSummaries_.reserve(goals_.size());
  for (const Goal& g : goals_)
    goalSummaries_.push_back(
        GoalSummary{g.point, g.arrivalRadius * g.arrivalRadius,
                    g.kind == Goal::Kind::Point, g.exit});
  if (!planner_ || planner_->goalCount() != goals_.size())
    throw InputError("crowd: the planner does not answer for the scene's goals");
  for (std::size_t k = 0; k < obstacles_.size(); ++k) {
    validateSimple(obstacles_[k], fmt::format("obstacles[{}]", k));
    freeArea_.addStaticObstacle(obstacles_[k]);
  }
  // A continuum grid that overhangs the walkable box (its cell does not divide the box) has no
  // room for agents beyond the walls: those strips are covered.
  const Vec2 gridHi = settings_.grid.origin + settings_.grid.extent();
  const double sliver = 1e-9 * settings_.grid.dx;
  if (gridHi.x() > settings_.hi.x() + sliver) freeArea_.addStaticObstacle(rectangle(Vec2(settings_.hi.x(), settings_.lo.y()), gridHi));
  if (gridHi.y() > settings_.hi.y() + sliver) freeArea_.addStaticObstacle(rectangle(Vec2(settings_.lo.x(), settings_.hi.y()), gridHi));
  walkingDensity_.emplace(settings_.lo, settings_.hi, obstacles_, settings_.speedDensity);
  for (std::size_t k = 0; k < moving_.size(); ++k) {
    validateSimple(moving_[k].shape, fmt::format("moving obstacle {}", k));
    if (!moving_[k].velocity.allFinite() || !moving_[k].amplitude.allFinite() || !std::isfinite(moving_[k].frequency))
      throw InputError(fmt::format("moving obstacle {}: its motion is not finite", k));
  }
  placeMovingObstacles(0.0);
  for (std::size_t i = 0; i < agents_.size(); ++i) validateAgent(i, fmt::format("agent {}", agents_.id[i]));
  // Agents placed at random overlap; separate them before the first step so that the overlap
  // statistics measure the simulation, not the placement.
  CollisionResolutionParams relax = settings_.collision;
  relax.iterations = kRelaxSweeps;
  resolver_.resolve(agents_, obstacleIndex(), DomainBox{settings_.lo.cast<float>(), settings_.hi.cast<float>()}, relax);
  for (std::size_t k = 0; k < inflows_.size(); ++k) {
    const Inflow& f = inflows_[k];
    validateSimple(f.region, fmt::format("inflows[{}].region", k));
    Vec2 lo, hi;
    bounds(f.region, lo, hi);
    if ((lo.array() < settings_.lo.array()).any() || (hi.array() > settings_.hi.array()).any())
      throw InputError(fmt::format("inflows[{}].region: it reaches outside the domain [{}, {}] x [{}, {}]", k,
                                   settings_.lo.x(), settings_.hi.x(), settings_.lo.y(), settings_.hi.y()));
    if (!(f.rate > 0.0 || (f.recycle && f.rate == 0.0)) || !std::isfinite(f.rate))
      throw InputError(fmt::format(
          "inflows[{}].rate: expected a positive number of agents per second (0 only with 'recycle': true)", k));
    if (f.agent.goal >= goals_.size())
      throw InputError(fmt::format("inflows[{}].goal: there is no goal {}", k, f.agent.goal));
    Rng probe = rng_.split(~std::uint64_t(k));
    const Vec2 x = randomFreePoint(probe, f.region, f.agent.radius, obstacleIndex());
    if (!x.allFinite())
      throw InputError(fmt::format("inflows[{}].region: no room for an agent of radius {} m outside the obstacles", k,
                                   f.agent.radius));
    if (!std::isfinite(planner_->distance(f.agent.goal, x)))
      throw InputError(fmt::format("inflows[{}].goal: goal {} cannot be reached from the inflow region", k, f.agent.goal));
  }
  for (std::size_t s = 0; s < scripts_.size(); ++s) {
    const std::size_t i = indexOfId(scripts_[s].agentId);
    if (i == agents_.size() || agents_.model[i] != AgentModel::Scripted)
      throw InputError(fmt::format("scripts[{}]: agent {} is not a scripted agent of the scene", s, scripts_[s].agentId));
    if (scripts_[s].waypoints.empty()) throw InputError(fmt::format("scripts[{}]: no waypoints", s));
  }
}

std::size_t CrowdSimulation::indexOfId(std::uint64_t id) const {
  // Agents stay in id order: add() appends the next id, removeFlagged() keeps the order.
  const auto it = std::lower_bound(agents_.id.begin(), agents_.id.end(), id);
  return it != agents_.id.end() && *it == id ? static_cast<std::size_t>(it - agents_.id.begin()) : agents_.size();
}

Polygon MovingObstacle::at(double t) const {
  const Vec2 offset = velocity * t + amplitude * std::sin(2.0 * M_PI * frequency * t);
  Polygon p = shape;
  for (Vec2& v : p.vertices) v += offset;
  return p;
}

void CrowdSimulation::placeMovingObstacles(double t) {
  if (moving_.empty()) return;
  movingNow_.resize(moving_.size());
  for (std::size_t k = 0; k < moving_.size(); ++k) movingNow_[k] = moving_[k].at(t);
  allNow_ = obstacles_;
  allNow_.insert(allNow_.end(), movingNow_.begin(), movingNow_.end());
  allObstacles_ = StaticObstacles(allNow_, obstacleReach_);
}

std::vector<Polygon> CrowdSimulation::movingObstaclesNow() const {
  std::vector<Polygon> now;
  for (const MovingObstacle& m : moving_) now.push_back(m.at(time_));
  return now;
}

void CrowdSimulation::validateAgent(std::size_t i, const std::string& what) const {
  const Vec2 x = agents_.position[i].cast<double>();
  if (!x.allFinite() || (x.array() < settings_.lo.array()).any() || (x.array() > settings_.hi.array()).any())
    throw InputError(fmt::format("{}: position ({}, {}) is outside the domain [{}, {}] x [{}, {}]", what, x.x(), x.y(),
                                 settings_.lo.x(), settings_.hi.x(), settings_.lo.y(), settings_.hi.y()));
  if (!(agents_.radius[i] > 0.0f) || !(agents_.maxSpeed[i] >= 0.0f) || !std::isfinite(agents_.maxSpeed[i]))
    throw InputError(fmt::format("{}: radius must be > 0 and max speed >= 0", what));
  for (std::size_t k = 0; k < obstacles_.size(); ++k)
    if (contains(obstacles_[k], x))
      throw InputError(fmt::format("{}: position ({}, {}) is inside obstacles[{}]", what, x.x(), x.y(), k));
  for (std::size_t k = 0; k < movingNow_.size(); ++k)
    if (contains(movingNow_[k], x))
      throw InputError(fmt::format("{}: position ({}, {}) is inside moving obstacle {}", what, x.x(), x.y(), k));
  if (agents_.model[i] == AgentModel::Scripted) return;
  if (agents_.goal[i] >= goals_.size()) throw InputError(fmt::format("{}: there is no goal {}", what, agents_.goal[i]));
  if (!std::isfinite(planner_->distance(agents_.goal[i], x)))
    throw InputError(fmt::format("{}: goal {} cannot be reached from ({}, {})", what, agents_.goal[i], x.x(), x.y()));
}

double CrowdSimulation::maxSpeed() const {
  float radius = 0.0f, speed = 0.0f;
  extremes(agents_, inflows_, radius, speed);
  return speed;
}

void CrowdSimulation::plan() {
  // Preferred velocity along the planned path at the agent's maximum speed, slowed on the last
  // stretch to a point goal so that it stops there instead of oscillating around it.
  const bool straight = planner_->straightToPointGoals();
  parallelFor(0, agents_.size(), [&](std::size_t i) {
    if (agents_.model[i] == AgentModel::Scripted) return;
    const std::uint32_t g = agents_.goal[i];
    const GoalSummary& goal = goalSummaries_[g];
    const Vec2 x = agents_.position[i].cast<double>();
    double speed = agents_.maxSpeed[i];
    if (!goal.isPoint) {  // a region: arrived inside it
      if (!goal.exit && goals_[g].inside(x)) {
        agents_.preferredVelocity[i].setZero();
        return;
      }
      agents_.preferredVelocity[i] = (speed * planner_->direction(g, x)).cast<float>();
      return;
    }
    if (!goal.exit && withinArrival(x, goal.point, goal.arrival2)) {  // Goal::reached
      agents_.preferredVelocity[i].setZero();
      return;
    }
    const Vec2 d = goal.point - x;
    if (!goal.exit) speed = std::min(speed, d.norm());
    // The straight direction formed here from the compact copy, without a call per agent.
    const Vec2 direction = straight ? DirectPlanner::unitTowards(d) : planner_->direction(g, x);
    agents_.preferredVelocity[i] = (speed * direction).cast<float>();
  });
}

void CrowdSimulation::moveScripted(double dt) {
  for (std::size_t s = 0; s < scripts_.size(); ++s) {
    Script& script = scripts_[s];
    const std::size_t i = indexOfId(script.agentId);
    if (i == agents_.size()) continue;
    double budget = agents_.maxSpeed[i] * dt;
    Vec2 x = agents_.position[i].cast<double>();
    const Vec2 start = x;
    std::size_t& next = scriptProgress_[s];
    while (budget > 0.0 && next < script.waypoints.size()) {
      const Vec2 d = script.waypoints[next] - x;
      const double len = d.norm();
      if (len <= budget) {
        x = script.waypoints[next];
        budget -= len;
        ++next;
        if (next == script.waypoints.size() && script.loop) next = 0;
        if (len == 0.0 && script.loop && script.waypoints.size() == 1) break;
      } else {
        x += d * (budget / len);
        budget = 0.0;
      }
    }
    agents_.velocity[i] = ((x - start) / dt).cast<float>();
    agents_.position[i] = x.cast<float>();
  }
}

void CrowdSimulation::prepareLookahead(double dt) {
  using lookahead::LookaheadMethod;
  const lookahead::LookaheadSettings& la = settings_.lookahead;
  const std::size_t n = agents_.size();
  const bool orca = stats_.orcaAgents > 0;
  // The far levels' suggestions follow the agents (arrivals compact them, new agents have none
  // until the next refresh).
  farDirection_.resize(n, Vec2f::Zero());
  farOrca_.resize(n, Vec2f::Zero());
  farOrcaSet_.resize(n, 0);
  const bool discrete = la.enabled() && orca && la.method != LookaheadMethod::Continuum;
  const bool cascade = discrete && la.discreteSolve == lookahead::DiscreteSolve::Cascade;
  sinceRefresh_ += dt;
  const bool refresh = !refreshed_ || sinceRefresh_ >= la.refresh - 1e-9;
  lookahead::AgentLookahead::Needs needs;
  needs.tree = discrete && (!cascade || refresh);
  // Level 0 (the crowd now): the hybrid's weights and the continuum's last word for ORCA agents,
  // and the stress model's collision-free velocities (Golas ch. 4.3.3: Chapter 3's continuum).
  const bool stressed = stress_ && stats_.uicAgents > 0;
  needs.densities.now = (la.enabled() && orca && la.method != LookaheadMethod::Discrete) || stressed;
  const bool farWanted = la.enabled() && (stats_.uicAgents > 0 || needs.densities.now);
  needs.densities.far = farWanted && refresh;
  stats_.lookahead = {};
  if (!needs.tree && !needs.densities.now && !needs.densities.far) {
    applyFarSuggestions(true);
    return;
  }
  ahead_ = &lookahead_.prepare(agents_, obstacleIndex(), settings_.orca.neighbourDist, maxSpeed(), settings_.lo,
                               settings_.hi, needs);
  if (needs.densities.far || (cascade && refresh)) {
    refreshed_ = true;
    sinceRefresh_ = 0.0;
  }
  if (cascade && refresh) refreshDiscreteFarLevels();
  continuumVelocity_.resize(n);
  blendWeight_.assign(n, 0.0f);
  skipOrca_.assign(n, 0);
  continuumIterations_.assign(n, 0);
  continuumSolves_.assign(n, 0);
  const lookahead::FutureDensity& future = lookahead_.future();
  const bool far = needs.densities.far;
  parallelFor(0, n, [&](std::size_t i) {
    const AgentModel model = agents_.model[i];
    if (model == AgentModel::Scripted || (model == AgentModel::Orca && (!la.enabled() || la.method == LookaheadMethod::Discrete)))
      return;
    const Vec2f& x = agents_.position[i];
    const Vec2f& preferred = agents_.preferredVelocity[i];
    int iterations = 0, solves = 0;
    // Levels L..1: the direction they suggest, kept until the next refresh.
    if (far) {
      const lookahead::CascadeResult r = lookahead::continuumLookahead(future, la.continuum, x, agents_.velocity[i], preferred,
                                                                       agents_.maxSpeed[i], lookahead_.depth(i), 1);
      iterations += r.iterations;
      solves += r.solves;
      const double speed = r.velocity.norm();
      farDirection_[i] = r.solves > 0 && speed > 0.0 ? Vec2f((r.velocity / speed).cast<float>()) : Vec2f::Zero();
    }
    const float wanted = preferred.norm();
    const Vec2f suggested = farDirection_[i].squaredNorm() > 0.0f ? Vec2f(wanted * farDirection_[i]) : preferred;
    if (model == AgentModel::Uic && !stressed) {
      agents_.preferredVelocity[i] = suggested;  // the UIC decides at level 0
    } else {
      if (model == AgentModel::Orca && la.method == LookaheadMethod::Hybrid) {
        const lookahead::FutureDensity::Flow flow = future.flow(x.cast<double>());
        const double w = lookahead::blendWeight(flow.density, flow.speedDeviation, flow.meanVelocity.norm(), la.blend);
        blendWeight_[i] = static_cast<float>(w);
        skipOrca_[i] = w >= 1.0;
      }
      // Level 0: eq. 3.2 on the crowd now, towards the far levels' suggestion: the stress model's
      // collision-free velocity f(rho) v* (eq. 4.9), or the ORCA agent's continuum answer.
      if (model == AgentModel::Uic || la.method == LookaheadMethod::Continuum || blendWeight_[i] > 0.0f) {
        const lookahead::CascadeResult r = lookahead::continuumLookahead(future, la.continuum, x, agents_.velocity[i],
                                                                         suggested, agents_.maxSpeed[i], 0, 0);
        iterations += r.iterations;
        solves += r.solves;
        continuumVelocity_[i] = r.velocity.cast<float>();
      }
    }
    continuumIterations_[i] = iterations;
    continuumSolves_[i] = solves;
  });
  LookaheadStepStats st;
  double weights = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    st.iterations += static_cast<std::size_t>(continuumIterations_[i]);
    st.solves += static_cast<std::size_t>(continuumSolves_[i]);
    if (agents_.model[i] == AgentModel::Orca && la.method == LookaheadMethod::Hybrid) {
      ++st.blended;
      weights += blendWeight_[i];
    }
  }
  st.meanWeight = st.blended > 0 ? weights / double(st.blended) : 0.0;
  stats_.lookahead = st;
  if (cascade) applyFarSuggestions(false);
}

// The discrete cascade's far levels (lookahead::farLevelsVelocity) for every ORCA agent that
// looks ahead, kept per unit of its preferred speed until the next refresh.
void CrowdSimulation::refreshDiscreteFarLevels() {
  const float invTau = 1.0f / settings_.orca.timeHorizon;
  parallelFor(0, agents_.size(), [&](std::size_t i) {
    farOrcaSet_[i] = 0;
    const float wanted = agents_.preferredVelocity[i].norm();
    if (agents_.model[i] != AgentModel::Orca || lookahead_.depth(i) == 0 || wanted <= 0.0f) return;
    FarScratch& s = farScratch_.local();
    const Vec2f v = lookahead::farLevelsVelocity(*ahead_, static_cast<std::uint32_t>(i), agents_.position[i], agents_.velocity[i],
                                                 agents_.radius[i], invTau, agents_.preferredVelocity[i], agents_.maxSpeed[i],
                                                 s.planes, s.projected);
    farOrca_[i] = v / wanted;
    farOrcaSet_[i] = 1;
  });
}

// Between refreshes agents walk towards the far levels' last suggestion: the ORCA agents of the
// discrete cascade, and with `uic` the UIC agents (which otherwise take theirs in
// prepareLookahead's pass).
void CrowdSimulation::applyFarSuggestions(bool uic) {
  parallelFor(0, agents_.size(), [&](std::size_t i) {
    Vec2f& preferred = agents_.preferredVelocity[i];
    if (agents_.model[i] == AgentModel::Orca && farOrcaSet_[i]) preferred = preferred.norm() * farOrca_[i];
    if (uic && agents_.model[i] == AgentModel::Uic && farDirection_[i].squaredNorm() > 0.0f)
      preferred = preferred.norm() * farDirection_[i];
  });
}

void CrowdSimulation::moveOrca(double dt) {
  if (stats_.orcaAgents == 0) return;
  using lookahead::LookaheadMethod;
  orcaVelocity_.resize(agents_.size());
  const bool ahead = settings_.lookahead.enabled();
  const LookaheadMethod method = ahead ? settings_.lookahead.method : LookaheadMethod::Discrete;
  // The single solve puts the far levels into level 0's program; the cascade has already made
  // their answer each agent's preferred velocity.
  const bool single = ahead && settings_.lookahead.discreteSolve == lookahead::DiscreteSolve::Single;
  if (method != LookaheadMethod::Continuum)
    orca_.computeVelocities(agents_, obstacleIndex(), settings_.orca, static_cast<float>(dt), orcaVelocity_,
                            single ? ahead_ : nullptr, method == LookaheadMethod::Hybrid ? std::span<const std::uint8_t>(skipOrca_)
                                                                                        : std::span<const std::uint8_t>());
  const float h = static_cast<float>(dt);
  parallelFor(0, agents_.size(), [&](std::size_t i) {
    if (agents_.model[i] != AgentModel::Orca) return;
    // ORCA's answers and the continuum's keep within the agent's maximum speed, and so does their
    // blend (eq. 3.11, each part computed only where its weight is not zero).
    Vec2f v = orcaVelocity_[i];
    if (method == LookaheadMethod::Continuum) {
      v = continuumVelocity_[i];
    } else if (method == LookaheadMethod::Hybrid) {
      const float w = blendWeight_[i];
      v = w >= 1.0f ? continuumVelocity_[i] : (w > 0.0f ? Vec2f((1.0f - w) * v + w * continuumVelocity_[i]) : v);
    }
    agents_.velocity[i] = v;
    agents_.position[i] += h * v;
  });
}

// Each agent's speed on the fundamental diagram for the density ahead (walking_density.hpp), for
// the UIC agents' step.
void CrowdSimulation::walkingSpeeds() {
  const std::size_t n = agents_.size();
  walkDensity_.resize(n);
  walkSpeed_.resize(n);
  walkingDensity_->measure(agents_.position, agents_.preferredVelocity, agents_.maxSpeed, walkDensity_, walkSpeed_);
}

void CrowdSimulation::splitContinuumAgents() {
  uicIndex_.clear();
  discCentres_.clear();
  discRadii_.clear();
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    if (agents_.model[i] == AgentModel::Uic) {
      uicIndex_.push_back(static_cast<std::uint32_t>(i));
    } else {
      // Individually controlled agents are obstacles of the continuum (ch. 4.4.3).
      discCentres_.push_back(agents_.position[i]);
      discRadii_.push_back(agents_.radius[i]);
    }
  }
}

void CrowdSimulation::moveUic(double dt) {
  discCentres_.clear();
  discRadii_.clear();
  std::span<const Vec2f> position = agents_.position, preferred = agents_.preferredVelocity;
  // Walking speeds: v_max of the continuum (renorm) and the cap below.
  const std::span<const float> walking = settings_.speedDensity.enabled ? std::span<const float>(walkSpeed_)
                                                                        : std::span<const float>(agents_.maxSpeed);
  std::span<const float> speed = walking;
  std::span<Vec2f> velocity = agents_.velocity;
  // All agents UIC (the usual case): the grid transfers read the agents' own arrays. Otherwise the
  // UIC agents are compacted into contiguous arrays.
  const bool allUic = stats_.uicAgents == agents_.size();
  if (!allUic) {
    splitContinuumAgents();
    uicVelocity_.resize(uicIndex_.size());
    gatherContinuum<Vec2f>(agents_.position, uicPosition_);
    gatherContinuum<Vec2f>(agents_.preferredVelocity, uicPreferred_);
    gatherContinuum<float>(walking, uicSpeed_);
    position = uicPosition_;
    preferred = uicPreferred_;
    speed = uicSpeed_;
    velocity = uicVelocity_;
  }
  const std::size_t n = position.size();
  if (n > 0 && settings_.uic) {
    freeArea_.update(discCentres_, discRadii_, movingNow_);
    stats_.uic = uic_.project(position, preferred, speed, freeArea_.fraction(), dt, velocity);
  } else {
    std::copy(preferred.begin(), preferred.end(), velocity.begin());
    stats_.uic = UicStats{};
  }
  const float h = static_cast<float>(dt);
  parallelFor(0, n, [&](std::size_t k) {
    const std::size_t i = allUic ? k : uicIndex_[k];
    // Eq. 4.7 is the optimum under |v| <= v_max. The outer psolve of eq. 4.20 comes after renorm
    // and corrects last step's overdensity within one step, which can ask for several times v_max
    // where a crowd presses into a bottleneck (3 m/s at the 95th percentile at a 1.2 m door);
    // people cannot walk that fast, so the correction is spread over several steps instead.
    Vec2f v = velocity[k];
    const float norm = v.norm();
    if (norm > speed[k]) v *= speed[k] / norm;
    agents_.velocity[i] = v;
    agents_.position[i] += h * v;
  });
}

void CrowdSimulation::moveStressed(double dt) {
  stats_.uic = UicStats{};
  stats_.stress = {};
  splitContinuumAgents();
  const std::size_t n = uicIndex_.size();
  if (n == 0) return;
  freeArea_.update(discCentres_, discRadii_, movingNow_);
  gatherContinuum<Vec2f>(agents_.position, uicPosition_);
  gatherContinuum<Vec2f>(agents_.velocity, uicVelocity_);
  gatherContinuum<Vec2f>(continuumVelocity_, uicPreferred_);  // v_cf of prepareLookahead
  stats_.stress = stress_->step(uicPosition_, uicVelocity_, uicPreferred_, freeArea_.fraction(), dt);
  parallelFor(0, n, [&](std::size_t k) {
    const std::size_t i = uicIndex_[k];
    agents_.position[i] = uicPosition_[k];
    agents_.velocity[i] = uicVelocity_[k];
  });
}

CrowdSimulation::FreeWalkers CrowdSimulation::freeWalkers() {
  const std::size_t n = agents_.size();
  if (n == 0) return {};
  // The step's walking-speed scratch serves here too: the next step measures afresh.
  walkDensity_.resize(n);
  walkSpeed_.resize(n);
  walkingDensity_->measure(agents_.position, agents_.preferredVelocity, agents_.maxSpeed, walkDensity_, walkSpeed_);
  FreeWalkers out;
  double sum = 0.0;
  for (std::size_t i = 0; i < n; ++i) {
    if (agents_.model[i] == AgentModel::Scripted || walkDensity_[i] >= kFreeDensity ||
        agents_.preferredVelocity[i].norm() < 0.5f * agents_.maxSpeed[i])
      continue;
    ++out.count;
    sum += agents_.velocity[i].norm();
  }
  out.meanSpeed = out.count > 0 ? sum / double(out.count) : 0.0;
  return out;
}

// A person entering through an inflow joins the stream already there: the new agent starts with
// the mean velocity of the agents in the inflow's region that walk to its goal (at rest where there
// are none; people in the region walking elsewhere, a counter-flow, are not its stream). Entering
// at rest into a moving crowd would be a velocity jump that the stress model (Golas ch. 4, eq. 4.3)
// relaxes over tau, showing as temporal pressure at the inlets that the crowd itself does not make.
Vec2f CrowdSimulation::streamVelocity(const Polygon& region, std::uint32_t goal) const {
  Vec2 lo, hi;
  bounds(region, lo, hi);
  Vec2f sum = Vec2f::Zero();
  std::size_t count = 0;
  for (std::size_t i = 0; i < agents_.size(); ++i) {
    if (agents_.goal[i] != goal) continue;
    const Vec2 x = agents_.position[i].cast<double>();
    if ((x.array() < lo.array()).any() || (x.array() > hi.array()).any() || !contains(region, x)) continue;
    sum += agents_.velocity[i];
    ++count;
  }
  return count > 0 ? Vec2f(sum / static_cast<float>(count)) : Vec2f::Zero();
}

void CrowdSimulation::arriveAndSpawn(double dt) {
  remove_.assign(agents_.size(), 0);
  // Scenes without exits (the circle: a goal per agent) skip the pass over every agent's goal.
  const auto exited = !anyExitGoal_ ? std::size_t(0) : static_cast<std::size_t>(parallelSum(agents_.size(), [&](std::size_t i) {
    if (agents_.model[i] == AgentModel::Scripted) return 0.0;
    const Goal& goal = goals_[agents_.goal[i]];
    if (!goal.exit || !goal.reached(agents_.position[i].cast<double>())) return 0.0;
    remove_[i] = 1;
    return 1.0;
  }));
  if (exited > 0) {
    for (std::size_t i = 0; i < agents_.size(); ++i)  // the events in agent order
      if (remove_[i]) exits_.push_back(ExitEvent{agents_.id[i], agents_.goal[i], time_});
    agents_.removeFlagged(remove_);
    lookahead_.removeFlagged(remove_);
    compactFlagged(farDirection_, remove_);
    compactFlagged(farOrca_, remove_);
    compactFlagged(farOrcaSet_, remove_);
  }
  stats_.exited = exited;

  // Each leaver is re-admitted whole by one of the recycling inflows open now, chosen by its id
  // (the same on a resumed run).
  recycling_.clear();
  for (std::size_t k = 0; k < inflows_.size(); ++k)
    if (inflows_[k].recycle && time_ >= inflows_[k].start && time_ <= inflows_[k].stop) recycling_.push_back(k);
  if (!recycling_.empty())
    for (std::size_t e = exits_.size() - exited; e < exits_.size(); ++e)
      inflowCredit_[recycling_[exits_[e].agentId % recycling_.size()]] += 1.0;

  stats_.spawned = 0;
  for (std::size_t k = 0; k < inflows_.size(); ++k) {
    const Inflow& f = inflows_[k];
    const double open = std::max(0.0, std::min(time_, f.stop) - std::max(time_ - dt, f.start));
    inflowCredit_[k] += f.rate * open;
    // An agent is due at a whole credit; the tolerance keeps round-off (rate x dt summed over many
    // steps, or a credit saved as float for --resume) from delaying it by a step.
    const auto due = [&] { return inflowCredit_[k] >= 1.0 - 1e-6; };
    if (!due()) continue;
    const Vec2f joining = streamVelocity(f.region, f.agent.goal);  // once for this step's agents
    while (due()) {
      inflowCredit_[k] -= 1.0;
      // Uniform in the region by rejection from its bounds (regions are checked to have area). The
      // stream depends only on the seed and the new agent's id, so a resumed run spawns the same.
      Rng rng = rng_.split(agents_.nextId);
      const Vec2 x = randomFreePoint(rng, f.region, f.agent.radius, obstacleIndex());
      if (!x.allFinite())
        throw SimulationError(fmt::format("inflows[{}]: no free room for a new agent in the region", k));
      AgentSpec spec = f.agent;
      spec.position = x.cast<float>();
      if (f.speeds.kind != SpeedDistribution::Kind::Fixed) spec.maxSpeed = static_cast<float>(f.speeds.sample(rng));
      agents_.velocity[agents_.add(spec)] = joining;
      ++stats_.spawned;
    }
  }
}

void CrowdSimulation::step(double dt, StageTimers* timers) {
  StageTimers local;
  StageTimers& t = timers ? *timers : local;
  if (!(dt > 0.0) || !std::isfinite(dt)) throw SimulationError(fmt::format("crowd: invalid time step {}", dt));
  stats_.agents = agents_.size();
  // Agents of each model (one pass, in parallel: the count is exact whatever the order).
  struct ModelCounts {
    std::size_t uic = 0, orca = 0;
  };
  const ModelCounts counts = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, agents_.size(), 1 << 14), ModelCounts{},
      [&](const tbb::blocked_range<std::size_t>& r, ModelCounts c) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          c.uic += agents_.model[i] == AgentModel::Uic;
          c.orca += agents_.model[i] == AgentModel::Orca;
        }
        return c;
      },
      [](ModelCounts a, const ModelCounts& b) { return ModelCounts{a.uic + b.uic, a.orca + b.orca}; });
  stats_.uicAgents = counts.uic;
  stats_.orcaAgents = counts.orca;
  stats_.scriptedAgents = agents_.size() - counts.uic - counts.orca;
  if (!moving_.empty()) {
    ScopedStage s(t, "crowd: moving obstacles");
    placeMovingObstacles(time_ + dt);  // where they are at the end of the step
  }
  {
    ScopedStage s(t, "crowd: planning");
    plan();
  }
  if (settings_.lookahead.enabled() || stress_) {
    ScopedStage s(t, "crowd: lookahead");
    prepareLookahead(dt);
  }
  stepStartVelocity_ = agents_.velocity;
  {
    ScopedStage s(t, "crowd: scripted + orca");
    moveScripted(dt);
    moveOrca(dt);
  }
  if (stress_) {
    ScopedStage s(t, "crowd: stress");
    moveStressed(dt);
  } else {
    if (settings_.speedDensity.enabled && stats_.uicAgents > 0) {
      ScopedStage s(t, "crowd: walking speeds");
      walkingSpeeds();
    }
    ScopedStage s(t, "crowd: uic");
    moveUic(dt);
  }
  // The domain's sides are walls, whether or not collision resolution runs.
  const Vec2f lo = settings_.lo.cast<float>(), hi = settings_.hi.cast<float>();
  parallelFor(0, agents_.size(), [&](std::size_t i) {
    agents_.position[i] = agents_.position[i].cwiseMax(lo + Vec2f::Constant(agents_.radius[i]))
                              .cwiseMin(hi - Vec2f::Constant(agents_.radius[i]));
  });
  if (settings_.collisionResolution) {
    ScopedStage s(t, "crowd: collisions");
    resolver_.resolve(agents_, obstacleIndex(),
                      DomainBox{settings_.lo.cast<float>(), settings_.hi.cast<float>()}, settings_.collision);
  }
  {
    ScopedStage s(t, "crowd: inconsistency");
    lookahead_.record(stepStartVelocity_, agents_.velocity, dt);
  }
  time_ += dt;
  {
    ScopedStage s(t, "crowd: exits + inflows");
    arriveAndSpawn(dt);
  }
}

}  // namespace msim::crowd
