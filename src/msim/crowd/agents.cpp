#include "msim/crowd/agents.hpp"

#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/hilbert_sort.h>

namespace msim::crowd {

void sortSpatially(std::vector<Vec2>& points) {
  using Point = CGAL::Exact_predicates_inexact_constructions_kernel::Point_2;
  std::vector<Point> sorted;
  sorted.reserve(points.size());
  for (const Vec2& p : points) sorted.emplace_back(p.x(), p.y());
  CGAL::hilbert_sort(sorted.begin(), sorted.end());  // median policy: no randomness
  for (std::size_t i = 0; i < points.size(); ++i) points[i] = Vec2(sorted[i].x(), sorted[i].y());
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
