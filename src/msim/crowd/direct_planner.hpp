#pragma once
// The trivial global planner for scenes without static obstacles: walk straight at the goal.
// Exact there (the straight line is the shortest path), it needs no precomputation or memory per
// goal, so it serves scenes where every agent has a goal of its own (the circle of Fig. 4.5,
// where each agent heads for the diametrically opposite point).
#include <vector>

#include "msim/crowd/goal.hpp"
#include "msim/crowd/planner.hpp"

namespace msim::crowd {

class DirectPlanner final : public GlobalPlanner {
 public:
  explicit DirectPlanner(std::vector<Goal> goals);
  std::size_t goalCount() const override { return goals_.size(); }
  // Towards the goal point, or the closest point of a region goal (zero inside it).
  Vec2 direction(std::size_t goal, const Vec2& position) const override;
  double distance(std::size_t goal, const Vec2& position) const override;
  bool straightToPointGoals() const override { return true; }
  // The unit vector along d (from an agent to its target), zero when the agent is there.
  static Vec2 unitTowards(const Vec2& d) {
    const double n = d.norm();
    return n > 1e-12 ? Vec2(d / n) : Vec2::Zero();
  }

 private:
  Vec2 target(std::size_t goal, const Vec2& position) const;
  std::vector<Goal> goals_;
};

}  // namespace msim::crowd
