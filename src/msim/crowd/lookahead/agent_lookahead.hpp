#pragma once
// Long-range avoidance for the crowd's agents (Golas ch. 3.5-3.9), the state it keeps from step to
// step: each agent's deviation samples (v(n) - v(n-1)) / dt, forgotten exponentially with
// a half-life of half the metric window tau_w (the seed's optional down-weighting of older
// samples), from which each step takes
//   - the local inconsistency metric sigma_j: the moments of the agents within about R of j
//     pooled (on a grid of cells R wide, the agent's cell and its eight neighbours: the seed
//     samples the smooth metric on a grid too),
//   - the depth L_j = min(L(sigma_j), the deepest level whose extrapolated position j sees without
//     an obstacle in between) (curtailing.hpp),
//   - the agent tree of the clusters (discrete lookahead, ORCA agents),
//   - and the pyramid of future densities (continuum lookahead: the UIC agents, and the ORCA
//     agents in the continuum and hybrid methods);
// and the scene's metric, every agent's samples pooled.
#include <cstdint>
#include <limits>
#include <span>
#include <vector>

#include "msim/crowd/agents.hpp"
#include "msim/crowd/lookahead/blending.hpp"
#include "msim/crowd/lookahead/continuum_lookahead.hpp"
#include "msim/crowd/lookahead/discrete_lookahead.hpp"
#include "msim/crowd/lookahead/future_density.hpp"
#include "msim/crowd/lookahead/inconsistency.hpp"
#include "msim/crowd/obstacle_index.hpp"

namespace msim::crowd::lookahead {

// How ORCA agents look ahead: the discrete lookahead in their linear program (ch. 3.6), the
// continuum one instead of ORCA (ch. 3.5, "Cont LA"), or the two blended per agent by the local
// density and velocity spread (ch. 3.9, "Hyb LA"). UIC agents always take the continuum lookahead
// as their preferred velocity (the UIC then decides at level 0).
enum class LookaheadMethod { Discrete, Continuum, Hybrid };

// How the discrete lookahead's far levels meet level 0: in ORCA's one linear program with the
// neighbours (the seed's single solve, ch. 3.6), or solved apart as the generic cascade of Fig. 3.4
// does, their answer level 0's preferred velocity, asked again every `refresh` seconds.
enum class DiscreteSolve { Single, Cascade };

struct LookaheadSettings {
  int levels = 0;             // i_max; 0: no lookahead
  double baseStep = 0.01;     // dt of the horizons dt_i = 2^(i-1) dt [s] (the seed's step)
  double coarsening = 2.0;    // c: effective radii r / c^i
  double sigmaMax = std::numeric_limits<double>::infinity();  // curtailing; infinity: constant lookahead
  double metricWindow = 0.4;  // tau_w [s]
  MetricMode metricMode = MetricMode::SqrtEigenvalueSum;
  LookaheadMethod method = LookaheadMethod::Discrete;
  DiscreteSolve discreteSolve = DiscreteSolve::Single;
  double cell = 1.0;          // h_0: level 0's cell in the future-density pyramid [m]
  // How often the far levels (1..L) of the continuum lookahead and of the discrete cascade are
  // asked again [s]; in between each agent keeps what they suggested (0: every step, as the seed).
  // The continuum's horizons are seconds, and asking them every step cost as much as the UIC step
  // itself.
  double refresh = 1.0;
  ContinuumSettings continuum;
  BlendThresholds blend;
  bool enabled() const { return levels > 0; }
};

class AgentLookahead {
 public:
  explicit AgentLookahead(const LookaheadSettings& settings = {}) : settings_(settings) {}
  const LookaheadSettings& settings() const { return settings_; }

  // What prepare() builds besides the depths: the agent tree (discrete lookahead) and the future
  // densities (continuum lookahead): level 0 (the crowd now: the hybrid's weights and the
  // continuum's last word; the UIC agents have their own) and the far levels.
  struct Needs {
    bool tree = false;
    DensityLevels densities{false, false};
  };
  // Before the agents move: depths for the agents as they stand and what `needs` asks for, the
  // future densities over the walkable box [lo, hi]. neighbourDist is ORCA's R, maxSpeed the
  // fastest any agent walks.
  const DiscreteLookahead& prepare(const Agents& agents, const StaticObstacles& obstacles, double neighbourDist,
                                   double maxSpeed, const Vec2& lo, const Vec2& hi, const Needs& needs);
  const FutureDensity& future() const { return future_; }
  // L_j of the last prepare().
  int depth(std::size_t agent) const { return depth_[agent]; }
  // After a step of dt that took every agent from `previous` to `current` velocities (the same
  // agents in the same order): the samples (current - previous) / dt, except each agent's first.
  // Every agent's: the metric describes the crowd whichever model moves it.
  void record(std::span<const Vec2f> previous, std::span<const Vec2f> current, double dt);
  // The agent list changed: removed ones (flags as Agents::removeFlagged) and new ones appended
  // (no samples yet). Call before prepare() whenever agents come or go.
  void removeFlagged(const std::vector<std::uint8_t>& remove);
  void resize(std::size_t agents);

  // Each agent's local metric now: the samples of the agents in its cell (side `cell`, R in
  // prepare()) and the eight around it pooled; `cells` is scratch.
  void localInconsistency(const Agents& agents, double cell, std::vector<DeviationMoment>& cells,
                          std::vector<float>& sigma) const;
  // Every agent's samples in the window pooled [m/s^2 or m^2/s^4 by the metric mode].
  double sceneInconsistency() const;

 private:
  LookaheadSettings settings_;
  std::vector<DeviationMoment> moments_;
  // Whether the agent has walked a step: its first velocity comes from rest (a new agent's 0),
  // which is the scene's start rather than a turn or a stop of its walk, and is not sampled.
  std::vector<std::uint8_t> walked_;
  std::vector<float> sigma_;
  std::vector<std::uint8_t> depth_;
  std::vector<DeviationMoment> cells_;
  DiscreteLookahead lookahead_;
  FutureDensity future_;
};

}  // namespace msim::crowd::lookahead
