#include "msim/crowd/lookahead/discrete_lookahead.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace msim::crowd::lookahead {

namespace {

// Squared nearest and farthest distances from (x, y) to the points of the box [lo, hi].
float nearestInBox2(float x, float y, const Vec2f& lo, const Vec2f& hi) {
  const float dx = std::max({lo.x() - x, x - hi.x(), 0.0f}), dy = std::max({lo.y() - y, y - hi.y(), 0.0f});
  return dx * dx + dy * dy;
}
float farthestInBox2(float x, float y, const Vec2f& lo, const Vec2f& hi) {
  const float dx = std::max(std::abs(x - lo.x()), std::abs(hi.x() - x)), dy = std::max(std::abs(y - lo.y()), std::abs(hi.y() - y));
  return dx * dx + dy * dy;
}

// The levels at which a node may stand for its members as one cluster (bit i for level i): at
// most 2^(i-1) members, no gap wider than an agent walks within dt_i (or 4 r), and a drift apart
// of at most a diameter by dt_i (discrete_lookahead.hpp).
std::uint32_t clusterLevels(const DiscreteLookahead& l, const AgentTree::Node& n) {
  std::uint32_t levels = 0;
  const float maxSpeed = static_cast<float>(l.schedule.maxSpeed);
  for (int i = 1; i <= l.schedule.levels; ++i) {
    const float horizon = l.horizon[static_cast<std::size_t>(i)];
    const bool fits = n.count <= (1u << (i - 1)) && n.separation <= std::max(maxSpeed * horizon, 4.0f * n.radius) &&
                      n.velocitySpread * horizon <= 2.0f * n.radius;
    levels |= static_cast<std::uint32_t>(fits) << i;
  }
  return levels;
}

}  // namespace

void DiscreteLookahead::tabulate() {
  if (schedule.levels > kMaxLevels) throw std::invalid_argument("lookahead: at most 16 levels");
  for (int i = 0; i <= schedule.levels + 1; ++i) {
    horizon[static_cast<std::size_t>(i)] = static_cast<float>(schedule.horizon(i));
    bandStart2[static_cast<std::size_t>(i)] = static_cast<float>(schedule.bandStart(i) * schedule.bandStart(i));
    shrink[static_cast<std::size_t>(i)] = static_cast<float>(schedule.effectiveRadius(1.0, i));
  }
  bandEnds2.fill(std::numeric_limits<float>::infinity());
  for (int i = 1; i <= schedule.levels + 1; ++i) bandEnds2[static_cast<std::size_t>(i - 1)] = bandStart2[static_cast<std::size_t>(i)];
}

void appendLookaheadPlanes(const DiscreteLookahead& l, std::span<const LookaheadAgent> batch, float invTau,
                           std::span<std::vector<HalfPlane>> planes) {
  constexpr std::size_t kLanes = kLookaheadBatch;
  if (batch.size() > kLanes || planes.size() < batch.size())
    throw std::invalid_argument("appendLookaheadPlanes: at most kLookaheadBatch agents, a plane list each");
  if (l.tree.empty()) return;
  const HorizonSchedule& s = l.schedule;
  // Lanes past the batch and agents that do not look ahead reach nothing.
  std::array<float, kLanes> px{}, py{}, reach2{};
  std::uint32_t everyone = 0;
  for (std::size_t a = 0; a < batch.size(); ++a) {
    const int depth = std::min<int>(l.depth[batch[a].self], s.levels);
    if (depth <= 0) continue;
    px[a] = batch[a].x.x();
    py[a] = batch[a].x.y();
    reach2[a] = l.bandStart2[static_cast<std::size_t>(depth) + 1];
    everyone |= 1u << a;
  }
  if (everyone == 0) return;
  const float near2 = l.bandStart2[1];
  // Constraint for agent a against a blocker at position xc moving at vc, of radius rc, seen at `level`.
  const auto avoid = [&](std::size_t a, const Vec2f& xc, const Vec2f& vc, float rc, int level) {
    const LookaheadAgent& g = batch[a];
    const float horizon = l.horizon[static_cast<std::size_t>(level)];
    planes[a].push_back(orcaHalfPlane(xc - g.x + (vc - g.v) * horizon, g.v - vc, g.r + rc, invTau, invTau, g.v, 0.5f, 1.0f));
  };
  // Depth-first, each pending node with the agents that opened it; a binary tree over n agents is
  // at most about log2(n) + 1 deep, and the stack holds at most one pending sibling per level.
  struct Pending {
    std::int32_t node;
    std::uint32_t agents;
  };
  std::array<Pending, 96> stack;
  std::size_t top = 0;
  stack[top++] = {0, everyone};
  std::array<float, kLanes> nearest2, farthest2;
  while (top > 0) {
    const auto [index, agents] = stack[--top];
    const AgentTree::Node& n = l.tree.node(index);
    for (std::size_t a = 0; a < kLanes; ++a) {
      nearest2[a] = nearestInBox2(px[a], py[a], n.lo, n.hi);
      farthest2[a] = farthestInBox2(px[a], py[a], n.lo, n.hi);
    }
    // Per agent: beyond every band, skip; reaching into level 0 (or holding the agent itself),
    // open unless all of it lies there; otherwise the node's band decides whether it is a cluster.
    std::uint32_t open = 0, banded = 0;
    for (std::size_t a = 0; a < kLanes; ++a) {
      const bool within = nearest2[a] < reach2[a], inner = nearest2[a] < near2;
      open |= static_cast<std::uint32_t>(within && inner && farthest2[a] >= near2) << a;
      banded |= static_cast<std::uint32_t>(within && !inner) << a;
    }
    open &= agents;
    banded &= agents;
    if (banded != 0) {
      const std::uint32_t clusters = clusterLevels(l, n);
      for (std::uint32_t m = banded; m != 0; m &= m - 1) {
        const std::size_t a = static_cast<std::size_t>(std::countr_zero(m));
        const int i = l.levelOfSquaredDistance(nearest2[a]);  // 1..depth: nearest2 < reach2
        if (clusters >> i & 1u) {
          const float horizon = l.horizon[static_cast<std::size_t>(i)];
          avoid(a, n.mean, n.velocity, clusterRadius(n, n.radius * l.shrink[static_cast<std::size_t>(i)], horizon), i);
        } else {
          open |= 1u << a;
        }
      }
    }
    if (open == 0) continue;
    if (n.left >= 0) {
      stack[top++] = {n.right, open};
      stack[top++] = {n.left, open};
      continue;
    }
    for (const std::uint32_t j : l.tree.agents().subspan(n.first, n.count)) {
      const Vec2f& xj = l.positions[j];
      for (std::uint32_t m = open; m != 0; m &= m - 1) {
        const std::size_t a = static_cast<std::size_t>(std::countr_zero(m));
        const float ex = xj.x() - px[a], ey = xj.y() - py[a], d2 = ex * ex + ey * ey;
        if (d2 < near2 || d2 >= reach2[a]) continue;  // level 0 (the agent itself too), or beyond the bands
        const int own = l.levelOfSquaredDistance(d2);
        avoid(a, xj, l.velocities[j], l.radii[j] * l.shrink[static_cast<std::size_t>(own)], own);
      }
    }
  }
}

Vec2f farLevelsVelocity(const DiscreteLookahead& lookahead, std::uint32_t self, const Vec2f& x, const Vec2f& v, float r,
                        float invTau, const Vec2f& preferred, float maxSpeed, std::vector<HalfPlane>& planes,
                        std::vector<HalfPlane>& scratch) {
  planes.clear();
  const LookaheadAgent agent{self, x, v, r};
  appendLookaheadPlanes(lookahead, std::span(&agent, 1), invTau, std::span(&planes, 1));
  if (planes.empty()) return preferred;
  return solveOrcaProgram(planes, 0, preferred, maxSpeed, scratch);
}

}  // namespace msim::crowd::lookahead
