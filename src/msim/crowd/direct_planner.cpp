#include "msim/crowd/direct_planner.hpp"

#include <cmath>

namespace msim::crowd {

DirectPlanner::DirectPlanner(std::vector<Goal> goals) : goals_(std::move(goals)) {}

Vec2 DirectPlanner::target(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_[goal];
  if (g.kind == Goal::Kind::Point) return g.point;
  if (g.inside(position)) return position;
  // The nearest region's nearest point: straight lines have no other way to choose an exit.
  Vec2 best = position;
  double bestSquared = INFINITY;
  for (const Polygon& r : g.regions) {
    const Vec2 c = closestBoundaryPoint(r, position);
    if ((c - position).squaredNorm() < bestSquared) bestSquared = (c - position).squaredNorm(), best = c;
  }
  return best;
}

Vec2 DirectPlanner::direction(std::size_t goal, const Vec2& position) const {
  return unitTowards(target(goal, position) - position);
}

double DirectPlanner::distance(std::size_t goal, const Vec2& position) const {
  return (target(goal, position) - position).norm();
}

}  // namespace msim::crowd
