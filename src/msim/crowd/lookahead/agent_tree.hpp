#pragma once
// A k-d tree over agents whose nodes carry their members' aggregates, the cluster candidates of
// the discrete lookahead (Golas ch. 3.6, Fig. 3.5): member count, mean position and velocity
// (eqs. 3.3-3.4), the largest member distance from the mean (for r_C, eq. 3.5) and velocity
// from the mean velocity, and the maximal
// separation, the largest gap between a member and its nearest fellow member, approximated as the
// seed does while building: the larger of the children's values and the gap between the children's
// bounding boxes (a leaf's exact). Leaves hold up to kLeafSize agents: where a leaf cannot stand for
// its members as one cluster the traversal takes them one by one, cheaper than two more levels of
// nodes. Built in O(n log n) by median splits along the longer side of each node's box; nothing is
// allocated once the buffers have grown.
#include <cstdint>
#include <span>
#include <vector>

#include "msim/crowd/agents.hpp"

namespace msim::crowd::lookahead {

class AgentTree {
 public:
  struct Node {
    Vec2f mean = Vec2f::Zero();      // x_C
    Vec2f velocity = Vec2f::Zero();  // v_C
    Vec2f lo = Vec2f::Zero(), hi = Vec2f::Zero();  // the members' bounding box
    float spread = 0.0f;             // max_j |x_j - x_C|
    float velocitySpread = 0.0f;     // max_j |v_j - v_C|
    float radius = 0.0f;             // the largest member's radius
    float separation = 0.0f;         // the approximate maximal separation
    std::uint32_t count = 0;
    std::uint32_t first = 0;         // members: agents()[first, first + count)
    std::int32_t left = -1, right = -1;  // children, -1 for a leaf (at most kLeafSize members)
  };

  static constexpr std::uint32_t kLeafSize = 4;

  // Builds over the agents at `positions` with `velocities` and `radii` (equal lengths).
  void build(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, std::span<const float> radii);

  bool empty() const { return nodes_.empty(); }
  std::size_t size() const { return nodes_.size(); }
  const Node& root() const { return nodes_.front(); }
  const Node& node(std::int32_t index) const { return nodes_[static_cast<std::size_t>(index)]; }
  // Agent indices in tree order (each node's members contiguous).
  std::span<const std::uint32_t> agents() const { return order_; }

 private:
  std::int32_t buildNode(std::uint32_t first, std::uint32_t count, std::span<const Vec2f> positions,
                         std::span<const Vec2f> velocities, std::span<const float> radii);

  std::vector<Node> nodes_;
  std::vector<std::uint32_t> order_;
};

}  // namespace msim::crowd::lookahead
