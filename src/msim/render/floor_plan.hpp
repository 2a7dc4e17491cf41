#pragma once
// Top views of 2D scenes: agents (or any 2D particles) as anti-aliased discs coloured by a field
// (speed, density, ...) through a colour map, over a floor with polygonal obstacles. This is the
// picture crowd simulations are judged by (issue #4: "agents in 2D crowds as discs on a floor
// plan, coloured by a chosen field").
#include <span>
#include <vector>

#include "msim/core/grid_spec.hpp"
#include "msim/core/vec.hpp"
#include "msim/io/png.hpp"

namespace msim::render {

// A perceptually ordered colour map from dark blue through teal and green to yellow (the shape
// of viridis, from five anchors interpolated in linear RGB); t is clamped to [0, 1].
Vec3 colourMap(double t);

struct FloorPlan {
  Vec2 lo = Vec2::Zero(), hi = Vec2::Ones();  // world box shown [m]
  int width = 800;                            // pixels across; the height keeps the aspect ratio
  Vec3 floor = Vec3(0.92, 0.92, 0.9);         // linear RGB
  Vec3 obstacle = Vec3(0.25, 0.25, 0.28);
  double valueMin = 0.0, valueMax = 1.0;      // the colour map's range
  // std::invalid_argument for an empty box or a width < 1.
  void validate() const;
};

// A field on the cells of a grid shown on the floor through the colour map (over [valueMin,
// valueMax] of the plan), cells holding 0 or less left as floor; obstacles and discs go on top.
struct CellField {
  GridSpec<2> spec;
  std::span<const float> values;  // spec.cellCount() values, x fastest
};

struct Discs {
  std::vector<Vec2> centres;  // [m]
  std::vector<double> radii;  // one per disc, or a single radius for all [m]
  std::vector<double> values; // one per disc (coloured by colourMap), or empty for mid-grey
};

// 8-bit sRGB picture, y up. Disc edges are anti-aliased by the pixel area they cover (analytic
// coverage of the disc edge across the pixel). std::invalid_argument for mismatched sizes,
// non-positive radii or non-finite data.
io::Image renderFloorPlan(const FloorPlan& plan, const Discs& discs,
                          const std::vector<std::vector<Vec2>>& obstacles = {}, const CellField* floorField = nullptr);

}  // namespace msim::render
