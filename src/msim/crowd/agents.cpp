#include "msim/crowd/agents.hpp"

#include <algorithm>
#include <cstdint>
#include <utility>

namespace msim::crowd {

namespace {
// The bits of v spread to the even bit positions (16 -> 32 bits).
std::uint32_t spreadBits(std::uint32_t v) {
  v = (v | (v << 8)) & 0x00FF00FFu;
  v = (v | (v << 4)) & 0x0F0F0F0Fu;
  v = (v | (v << 2)) & 0x33333333u;
  v = (v | (v << 1)) & 0x55555555u;
  return v;
}
}  // namespace

void sortSpatially(std::vector<Vec2>& points) {
  if (points.size() < 2) return;
  Vec2 lo = points[0], hi = points[0];
  for (const Vec2& p : points) {
    lo = lo.cwiseMin(p);
    hi = hi.cwiseMax(p);
  }
  // 2^16 steps per axis over the larger side: cells far below an agent's size.
  const double scale = 65535.0 / std::max((hi - lo).maxCoeff(), 1e-12);
  std::vector<std::pair<std::uint32_t, std::size_t>> keyed(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) {
    const auto x = static_cast<std::uint32_t>((points[i].x() - lo.x()) * scale);
    const auto y = static_cast<std::uint32_t>((points[i].y() - lo.y()) * scale);
    keyed[i] = {spreadBits(x) | (spreadBits(y) << 1), i};
  }
  std::sort(keyed.begin(), keyed.end());  // ties by input order: deterministic
  std::vector<Vec2> sorted(points.size());
  for (std::size_t i = 0; i < points.size(); ++i) sorted[i] = points[keyed[i].second];
  points.swap(sorted);
}

void Agents::reserve(std::size_t n) {
  position.reserve(n);
  velocity.reserve(n);
  preferredVelocity.reserve(n);
  radius.reserve(n);
  maxSpeed.reserve(n);
  goal.reserve(n);
  model.reserve(n);
  group.reserve(n);
  id.reserve(n);
}

std::size_t Agents::add(const AgentSpec& spec) {
  position.push_back(spec.position);
  velocity.push_back(Vec2f::Zero());
  preferredVelocity.push_back(Vec2f::Zero());
  radius.push_back(spec.radius);
  maxSpeed.push_back(spec.maxSpeed);
  goal.push_back(spec.goal);
  model.push_back(spec.model);
  group.push_back(spec.group);
  id.push_back(nextId++);
  return position.size() - 1;
}

namespace {
template <typename T>
void compact(std::vector<T>& v, const std::vector<std::uint8_t>& remove) {
  std::size_t out = 0;
  for (std::size_t i = 0; i < v.size(); ++i)
    if (!remove[i]) v[out++] = v[i];
  v.resize(out);
}
}  // namespace

void Agents::removeFlagged(const std::vector<std::uint8_t>& remove) {
  compact(position, remove);
  compact(velocity, remove);
  compact(preferredVelocity, remove);
  compact(radius, remove);
  compact(maxSpeed, remove);
  compact(goal, remove);
  compact(model, remove);
  compact(group, remove);
  compact(id, remove);
}

AgentSpec Agents::spec(std::size_t i) const {
  return AgentSpec{position[i], radius[i], maxSpeed[i], goal[i], model[i], group[i]};
}

}  // namespace msim::crowd
