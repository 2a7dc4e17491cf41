#include "msim/crowd/direct_planner.hpp"

namespace msim::crowd {

DirectPlanner::DirectPlanner(std::vector<Goal> goals) : goals_(std::move(goals)) {}

Vec2 DirectPlanner::target(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_[goal];
  if (g.kind == Goal::Kind::Point) return g.point;
  return contains(g.region, position) ? position : closestBoundaryPoint(g.region, position);
}

Vec2 DirectPlanner::direction(std::size_t goal, const Vec2& position) const {
  const Vec2 d = target(goal, position) - position;
  const double n = d.norm();
  return n > 1e-12 ? Vec2(d / n) : Vec2::Zero();
}

double DirectPlanner::distance(std::size_t goal, const Vec2& position) const {
  return (target(goal, position) - position).norm();
}

}  // namespace msim::crowd
