#include "msim/crowd/lookahead/agent_tree.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace msim::crowd::lookahead {

namespace {

// The gap between two boxes (0 when they touch or overlap).
float boxGap(const Vec2f& aLo, const Vec2f& aHi, const Vec2f& bLo, const Vec2f& bHi) {
  const Vec2f gap = (bLo - aHi).cwiseMax(aLo - bHi).cwiseMax(0.0f);
  return gap.norm();
}

}  // namespace

void AgentTree::build(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, std::span<const float> radii) {
  if (positions.size() != velocities.size() || positions.size() != radii.size())
    throw std::invalid_argument("agent tree: positions, velocities and radii differ in length");
  nodes_.clear();
  order_.resize(positions.size());
  std::iota(order_.begin(), order_.end(), 0u);
  if (positions.empty()) return;
  nodes_.reserve(2 * positions.size());
  buildNode(0, static_cast<std::uint32_t>(positions.size()), positions, velocities, radii);
}

std::int32_t AgentTree::buildNode(std::uint32_t first, std::uint32_t count, std::span<const Vec2f> positions,
                                  std::span<const Vec2f> velocities, std::span<const float> radii) {
  const auto index = static_cast<std::int32_t>(nodes_.size());
  nodes_.emplace_back();
  Node n;
  n.first = first;
  n.count = count;
  const auto begin = order_.begin() + first, end = begin + count;
  n.lo = n.hi = positions[*begin];
  for (auto it = begin; it != end; ++it) {
    n.lo = n.lo.cwiseMin(positions[*it]);
    n.hi = n.hi.cwiseMax(positions[*it]);
  }
  if (count > kLeafSize) {
    const int axis = (n.hi.x() - n.lo.x()) >= (n.hi.y() - n.lo.y()) ? 0 : 1;
    const std::uint32_t half = count / 2;
    std::nth_element(begin, begin + half, end, [&](std::uint32_t a, std::uint32_t b) {
      return positions[a][axis] < positions[b][axis] || (positions[a][axis] == positions[b][axis] && a < b);
    });
    n.left = buildNode(first, half, positions, velocities, radii);
    n.right = buildNode(first + half, count - half, positions, velocities, radii);
    const Node& l = nodes_[static_cast<std::size_t>(n.left)];
    const Node& r = nodes_[static_cast<std::size_t>(n.right)];
    const float wl = static_cast<float>(l.count) / static_cast<float>(count);
    n.mean = wl * l.mean + (1.0f - wl) * r.mean;
    n.velocity = wl * l.velocity + (1.0f - wl) * r.velocity;
    n.separation = std::max({l.separation, r.separation, boxGap(l.lo, l.hi, r.lo, r.hi)});
    n.radius = std::max(l.radius, r.radius);
  } else {
    // A leaf: its members' means, and as its separation the largest gap between one member and
    // the nearest other (exact at this size).
    for (auto it = begin; it != end; ++it) {
      n.mean += positions[*it] / static_cast<float>(count);
      n.velocity += velocities[*it] / static_cast<float>(count);
      n.radius = std::max(n.radius, radii[*it]);
      float nearest = count > 1 ? std::numeric_limits<float>::infinity() : 0.0f;
      for (auto other = begin; other != end; ++other)
        if (other != it) nearest = std::min(nearest, (positions[*it] - positions[*other]).norm());
      n.separation = std::max(n.separation, nearest);
    }
  }
  for (auto it = begin; it != end; ++it) {
    n.spread = std::max(n.spread, (positions[*it] - n.mean).norm());
    n.velocitySpread = std::max(n.velocitySpread, (velocities[*it] - n.velocity).norm());
  }
  nodes_[static_cast<std::size_t>(index)] = n;
  return index;
}

}  // namespace msim::crowd::lookahead
