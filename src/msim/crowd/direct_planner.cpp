#include "msim/crowd/direct_planner.hpp"

namespace msim::crowd {

DirectPlanner::DirectPlanner(std::vector<Goal> goals) : goals_(std::move(goals)) {}

Vec2 DirectPlanner::target(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_[goal];
  if (g.kind == Goal::Kind::Point) return g.point;
  return contains(g.region, position) ? position : closestBoundaryPoint(g.region, position);
}

Vec2 DirectPlanner::direction(std::size_t goal, const Vec2& position) const {
  return unitTowards(target(goal, position) - position);
}

double DirectPlanner::distance(std::size_t goal, const Vec2& position) const {
  return (target(goal, position) - position).norm();
}

}  // namespace msim::crowd
