#pragma once
// Where agents want to go: a point, or a set of regions (any point inside any of them counts as
// arrived). A set of several regions is a choice of exits: one navigation field is seeded from all
// of them, so each agent heads for the one nearest along its path. Exits are goals whose agents
// leave the scene on arrival (evacuations, outflow regions).
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

// Whether x lies within a point goal's arrival radius (given squared): the one test of arrival,
// shared by the goal and the planning step's compact copy of it.
inline bool withinArrival(const Vec2& x, const Vec2& point, double radius2) { return (x - point).squaredNorm() <= radius2; }

struct Goal {
  enum class Kind { Point, Region };
  Kind kind = Kind::Point;
  Vec2 point = Vec2::Zero();     // Kind::Point [m]
  std::vector<Polygon> regions;  // Kind::Region: one or more (a set of exits)
  double arrivalRadius = 0.5;    // Kind::Point: arrived within this distance [m]
  bool exit = false;             // arrived agents are removed from the scene

  // Kind::Region: x lies in one of the regions.
  bool inside(const Vec2& x) const {
    for (const Polygon& r : regions)
      if (contains(r, x)) return true;
    return false;
  }
  bool reached(const Vec2& x) const {
    return kind == Kind::Point ? withinArrival(x, point, arrivalRadius * arrivalRadius) : inside(x);
  }
};

}  // namespace msim::crowd
