#pragma once
// Where agents want to go: a point, or a region (any point inside counts as arrived). Exits are
// goals whose agents leave the scene on arrival (evacuations, outflow regions).
#include "msim/core/vec.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

struct Goal {
  enum class Kind { Point, Region };
  Kind kind = Kind::Point;
  Vec2 point = Vec2::Zero();  // Kind::Point [m]
  Polygon region;             // Kind::Region
  double arrivalRadius = 0.5; // Kind::Point: arrived within this distance [m]
  bool exit = false;          // arrived agents are removed from the scene

  bool reached(const Vec2& x) const {
    return kind == Kind::Point ? (x - point).squaredNorm() <= arrivalRadius * arrivalRadius : contains(region, x);
  }
};

}  // namespace msim::crowd
