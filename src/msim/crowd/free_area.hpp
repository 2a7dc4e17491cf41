#pragma once
// Free-area fractions of the crowd grid (Narain 2011, ch. 4.4.3): per cell, the fraction f in
// [0, 1] of its area NOT covered by obstacles. The UIC then caps the density of a cell at
// f * rho_max (sigma = f rho_max - rho), which handles obstacles without stair-stepping.
//
// Static polygons are clipped exactly against each cell they may overlap (Sutherland-Hodgman of
// the polygon against the cell rectangle, then the shoelace area) and accumulated once. Moving
// obstacles (scripted and ORCA agents, which ch. 4.4.3 treats as obstacles of the continuum) are
// discs whose exact intersection area with each overlapped cell is added per step.
//
// Overlapping obstacles: covered areas are summed and the sum is clamped to the cell area, so where
// obstacles overlap each other the free area is underestimated (conservative: the density cap is
// never raised by an overlap).
#include <span>

#include "msim/core/grid.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

// Exact area of polygon ∩ [lo, hi] (any orientation; a concave polygon is fine, the clip may leave
// zero-area slivers that add nothing) [m^2].
double clippedArea(const Polygon& polygon, const Vec2& lo, const Vec2& hi);
// Exact area of the disc (centre, radius) ∩ [lo, hi] [m^2].
double discRectangleArea(const Vec2& centre, double radius, const Vec2& lo, const Vec2& hi);

class FreeArea {
 public:
  // All cells free until obstacles are added.
  explicit FreeArea(const GridSpec<2>& grid);

  // Adds a static obstacle to the precomputed coverage (only the cells overlapping its bounds are
  // visited) and refreshes fraction() without discs. Throws InputError for fewer than 3 vertices
  // or a non-finite vertex.
  void addStaticObstacle(const Polygon& polygon);
  // fraction() = 1 - min(1, (static + this step's coverage) / cell area) for this step's discs
  // (scripted and ORCA agents) and moving obstacle polygons at their current place. No allocation
  // once warm. Throws InputError for a non-finite centre or radius or a negative radius, spans of
  // different sizes, or a polygon as addStaticObstacle() refuses.
  void update(std::span<const Vec2f> centres, std::span<const float> radii, std::span<const Polygon> moving = {});

  const GridSpec<2>& grid() const { return grid_; }
  // f per cell, cell-centred layout of grid().
  const Grid<float, 2>& fraction() const { return fraction_; }
  // Static coverage per cell [m^2], not clamped.
  const Grid<double, 2>& staticCoverage() const { return static_; }

 private:
  void refreshFraction();
  // Adds the exact covered area of the polygon to the cells it overlaps.
  void addPolygon(const Polygon& polygon, Grid<double, 2>& coverage);

  GridSpec<2> grid_;
  Grid<double, 2> static_;   // covered area of the static polygons
  Grid<double, 2> covered_;  // static_ plus this step's discs
  Grid<float, 2> fraction_;
  std::vector<Vec2> clipA_, clipB_;  // clipping scratch
};

}  // namespace msim::crowd
