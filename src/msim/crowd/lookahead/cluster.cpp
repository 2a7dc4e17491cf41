#include "msim/crowd/lookahead/cluster.hpp"

#include <algorithm>
#include <stdexcept>

namespace msim::crowd::lookahead {

Cluster clusterOf(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, float effectiveRadius) {
  if (positions.empty() || positions.size() != velocities.size())
    throw std::invalid_argument("lookahead cluster: needs at least one member and a velocity for each");
  Cluster c;
  c.members = static_cast<int>(positions.size());
  for (std::size_t j = 0; j < positions.size(); ++j) {
    c.position += positions[j];
    c.velocity += velocities[j];
  }
  c.position /= static_cast<float>(c.members);
  c.velocity /= static_cast<float>(c.members);
  float spread = 0.0f;
  for (const Vec2f& x : positions) spread = std::max(spread, (x - c.position).norm());
  c.radius = effectiveRadius + spread;
  return c;
}

}  // namespace msim::crowd::lookahead
