#pragma once
// The discrete lookahead of Golas ch. 3.6 on ORCA: besides its neighbours within R (level 0, plain
// ORCA), an agent avoids the agents of band i (horizons.hpp) as they will be dt_i ahead: each
// extrapolated in a straight line, x_j + v_j dt_i, with the effective radius r_j / c^i, and the
// agent's own position extrapolated likewise, all in the one linear program of the agent's ORCA
// step. Far agents are grouped (Fig. 3.5): a node of the agent tree whose nearest possible member
// lies in band i stands for its members as one cluster (eqs. 3.3-3.5) when it holds at most
// 2^(i-1) agents (the seed's target size dt_i / dt), no gap inside it lets an agent through that
// it could reach within dt_i (members' centres at most 4 r apart - two radii and a diameter - or
// at most the distance an agent walks within dt_i) and its members, extrapolated, drift apart by
// at most a diameter by then [assumptions: the seed leaves the quality threshold open (its notes
// suggest 2-4 diameters); a gap nobody can reach within the horizon is of no use to plan through,
// and a cluster of agents walking different ways, two crossing streams, would stand for neither].
// Its radius covers the members' extrapolated discs: r_f + max |x_j - x_C| + max |v_j - v_C| dt_i.
// A node that fails is opened. Deeper levels are cut per agent (curtailing.hpp): `depth` holds
// each agent's L_j.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "msim/crowd/lookahead/agent_tree.hpp"
#include "msim/crowd/lookahead/horizons.hpp"
#include "msim/crowd/orca.hpp"

namespace msim::crowd::lookahead {

struct DiscreteLookahead {
  // The schedule and, tabulated from it by tabulate() for the traversals, each level's
  // horizon dt_i, squared band start and radius factor 1 / c^i (levels <= kMaxLevels).
  static constexpr int kMaxLevels = 16;
  HorizonSchedule schedule;
  std::array<float, kMaxLevels + 2> horizon{}, bandStart2{}, shrink{};
  void tabulate();
  // The level whose band holds a distance, given squared (0 within R; HorizonSchedule's
  // levelOfDistance tabulated; the traversal compares squares, without square roots), -1 beyond.
  // Counts the band starts 1..levels + 1 at or below it in whole vectors, without a branch per band
  // (the traversal asks for every node and leaf member it meets).
  int levelOfSquaredDistance(float distance2) const {
    int below = 0;
    for (const float start2 : bandEnds2) below += distance2 >= start2;
    return below <= schedule.levels ? below : -1;
  }
  // bandStart2[1..levels + 1], then infinity: three vectors of eight, for levelOfSquaredDistance.
  std::array<float, 24> bandEnds2{};

  AgentTree tree;  // over `positions`
  std::span<const Vec2f> positions, velocities;
  std::span<const float> radii;
  std::span<const std::uint8_t> depth;  // L_j: the deepest level agent j looks at (0: plain ORCA)
};

// r_C (eq. 3.5) of a tree node seen `horizon` ahead with the members' effective radius r_f:
// r_f + max |x_j - x_C| + max |v_j - v_C| horizon, which covers every member's extrapolated disc.
inline float clusterRadius(const AgentTree::Node& node, float effectiveRadius, float horizon) {
  return effectiveRadius + node.spread + node.velocitySpread * horizon;
}

// An agent whose far levels a traversal collects: its index, position, velocity and radius.
struct LookaheadAgent {
  std::uint32_t self;
  Vec2f x, v;
  float r;
};
// The most agents one traversal serves.
inline constexpr std::size_t kLookaheadBatch = 8;

// Appends to planes[a] the lookahead constraints of batch[a] (at most kLookaheadBatch agents) for
// its levels 1..depth[self], ORCA's time horizon 1 / invTau. One depth-first traversal of the tree
// serves the batch: each node is loaded once, the agents' distance tests run side by side, and a
// node is opened for those agents that open it, so every agent gets the constraints, in the order,
// that a traversal of its own would give it. Nearby agents open mostly the same nodes, so a batch
// of neighbours costs little more than one of them.
void appendLookaheadPlanes(const DiscreteLookahead& lookahead, std::span<const LookaheadAgent> batch, float invTau,
                           std::span<std::vector<HalfPlane>> planes);

// The far levels on their own (the cascade of Fig. 3.4 with levels depth..1 taken in one linear
// program): the velocity nearest `preferred`, within maxSpeed, that avoids the agents and clusters
// of agent `self`'s levels 1..depth[self]; level 0, plain ORCA, then takes it as its preferred
// velocity, so far agents bend an agent's wish instead of binding its choice. Returns `preferred`
// where there is nothing far to avoid. `planes` and `scratch` are the caller's buffers.
Vec2f farLevelsVelocity(const DiscreteLookahead& lookahead, std::uint32_t self, const Vec2f& x, const Vec2f& v, float r,
                        float invTau, const Vec2f& preferred, float maxSpeed, std::vector<HalfPlane>& planes,
                        std::vector<HalfPlane>& scratch);

}  // namespace msim::crowd::lookahead
