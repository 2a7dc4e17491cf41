#include "msim/crowd/lookahead/discrete_lookahead.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <limits>
#include <stdexcept>

namespace msim::crowd::lookahead {

namespace {

// Squared nearest and farthest distances from x to the points of a box.
float nearestInBox2(const Vec2f& x, const Vec2f& lo, const Vec2f& hi) {
  return (lo - x).cwiseMax(x - hi).cwiseMax(0.0f).squaredNorm();
}
float farthestInBox2(const Vec2f& x, const Vec2f& lo, const Vec2f& hi) {
  return (x - lo).cwiseAbs().cwiseMax((hi - x).cwiseAbs()).squaredNorm();
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

void appendLookaheadPlanes(const DiscreteLookahead& l, std::uint32_t self, const Vec2f& x, const Vec2f& v, float r,
                           float invTau, std::vector<HalfPlane>& planes) {
  const HorizonSchedule& s = l.schedule;
  const int depth = std::min<int>(l.depth[self], s.levels);
  if (depth <= 0 || l.tree.empty()) return;
  const float reach2 = l.bandStart2[static_cast<std::size_t>(depth) + 1], near2 = l.bandStart2[1];
  // Constraint against a blocker at position xc moving at vc, of radius rc, seen at `level`.
  const auto avoid = [&](const Vec2f& xc, const Vec2f& vc, float rc, int level) {
    const float horizon = l.horizon[static_cast<std::size_t>(level)];
    planes.push_back(orcaHalfPlane(xc - x + (vc - v) * horizon, v - vc, r + rc, invTau, invTau, v, 0.5f, 1.0f));
  };
  // Depth-first; a binary tree over n agents is at most about log2(n) + 1 deep, and the stack holds
  // at most one pending sibling per level.
  std::array<std::int32_t, 96> stack;
  std::size_t top = 0;
  stack[top++] = 0;
  while (top > 0) {
    const AgentTree::Node& n = l.tree.node(stack[--top]);
    const float nearest2 = nearestInBox2(x, n.lo, n.hi);
    if (nearest2 >= reach2) continue;  // beyond every band
    if (nearest2 < near2) {
      // Reaches into level 0 (or holds the agent itself): open it, unless all of it lies there.
      if (farthestInBox2(x, n.lo, n.hi) < near2) continue;
    } else {
      const int level = l.levelOfSquaredDistance(nearest2);  // 1..depth: nearest2 < reach2
      if (n.count <= (1u << (level - 1))) {
        const float horizon = l.horizon[static_cast<std::size_t>(level)];
        const float walked = static_cast<float>(s.maxSpeed) * horizon, drift = n.velocitySpread * horizon;
        if (n.separation <= std::max(walked, 4.0f * n.radius) && drift <= 2.0f * n.radius) {
          avoid(n.mean, n.velocity, clusterRadius(n, n.radius * l.shrink[static_cast<std::size_t>(level)], horizon), level);
          continue;
        }
      }
    }
    if (n.left >= 0) {
      stack[top++] = n.right;
      stack[top++] = n.left;
      continue;
    }
    for (const std::uint32_t j : l.tree.agents().subspan(n.first, n.count)) {
      const float d2 = (l.positions[j] - x).squaredNorm();
      if (d2 < near2 || d2 >= reach2) continue;  // level 0 (the agent itself too), or beyond the bands
      const int own = l.levelOfSquaredDistance(d2);
      avoid(l.positions[j], l.velocities[j], l.radii[j] * l.shrink[static_cast<std::size_t>(own)], own);
    }
  }
}

Vec2f farLevelsVelocity(const DiscreteLookahead& lookahead, std::uint32_t self, const Vec2f& x, const Vec2f& v, float r,
                        float invTau, const Vec2f& preferred, float maxSpeed, std::vector<HalfPlane>& planes,
                        std::vector<HalfPlane>& scratch) {
  planes.clear();
  appendLookaheadPlanes(lookahead, self, x, v, r, invTau, planes);
  if (planes.empty()) return preferred;
  return solveOrcaProgram(planes, 0, preferred, maxSpeed, scratch);
}

}  // namespace msim::crowd::lookahead
