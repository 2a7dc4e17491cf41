#pragma once
// A cluster of distant agents seen as one blocker in the discrete lookahead (Golas ch. 3.6,
// eqs. 3.3-3.5): x_C and v_C the members' mean position and velocity, and a radius
// r_C = r_f + max_j |x_j - x_C| that covers every member's disc of the level's effective radius
// r_f.
#include <span>

#include "msim/crowd/agents.hpp"

namespace msim::crowd::lookahead {

struct Cluster {
  Vec2f position = Vec2f::Zero();  // x_C
  Vec2f velocity = Vec2f::Zero();  // v_C
  float radius = 0.0f;             // r_C
  int members = 0;
};

// The cluster of the agents at `positions` with `velocities` (the same length, at least one),
// each of effective radius `effectiveRadius`.
Cluster clusterOf(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, float effectiveRadius);

}  // namespace msim::crowd::lookahead
