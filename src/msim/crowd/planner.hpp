#pragma once
// Global planning (Narain 2011, ch. 4.3.1): the direction of the initial segment of each agent's
// planned path around static obstacles, ignoring other agents. Two implementations: a grid
// navigation field per goal (fast marching on the eikonal equation) and the constrained-Delaunay
// roadmap of the seed. Planners are built once per static scene (the cache the seed's step 2
// allows) and are then queried concurrently from many threads: every query is const.
#include <cstddef>

#include "msim/core/vec.hpp"

namespace msim::crowd {

class GlobalPlanner {
 public:
  virtual ~GlobalPlanner() = default;
  virtual std::size_t goalCount() const = 0;
  // Unit direction in which an agent at `position` heading for goal `goal` should walk; zero when
  // it is at the goal or cannot reach it.
  virtual Vec2 direction(std::size_t goal, const Vec2& position) const = 0;
  // Length of the planned path to the goal [m]; +infinity where the goal cannot be reached.
  virtual double distance(std::size_t goal, const Vec2& position) const = 0;
  // True when direction() towards a point goal is the unit vector straight at the point (no
  // obstacles to plan around), so that callers stepping many agents may form it themselves from a
  // compact copy of the goal points instead of calling through here per agent.
  virtual bool straightToPointGoals() const { return false; }
};

}  // namespace msim::crowd
