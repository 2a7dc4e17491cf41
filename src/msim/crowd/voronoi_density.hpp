#pragma once
// Voronoi density (Steffen & Seyfried 2010, "Methods for measuring pedestrian density, flow,
// speed and direction with minimal scatter", Physica A 389): each agent owns its Voronoi cell and
// its local density is 1 / |cell|. Unlike counting agents in a window, this has no discretisation
// jumps, so fundamental diagrams scatter less. Cells of agents at the edge of the crowd are
// unbounded; they are clipped to a disc of radius R around the agent and to the domain box, so
// every agent gets a finite density (an isolated agent gets 1 / (pi R^2)).
#include <optional>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

struct VoronoiOptions {
  double cutoffRadius = 1.0;  // R: cells are clipped to the disc |x - x_i| <= R [m]; > 0
  // Cells are clipped to this box too (walls of a corridor, the scene bounds); every agent must
  // lie inside it. Without one, only the disc clips.
  std::optional<Vec2> domainLo, domainHi;
};

// The clipped Voronoi cells of a frame. Agents at the same position (to 2^-31 of the crowd's
// extent) share one cell, so each of them owns 1/multiplicity of it.
struct VoronoiCells {
  std::vector<Vec2> centres;               // agent positions [m]
  std::vector<Polygon> cells;              // Voronoi cell ∩ domain box ∩ the disc's bounding square
  std::vector<int> multiplicity;           // agents at this agent's position (>= 1)
  double cutoffRadius = 1.0;               // R [m]

  // |cell_i ∩ disc(x_i, R)| / multiplicity_i [m^2]
  double area(std::size_t i) const;
};

// Voronoi diagram of the positions (Boost.Polygon), then each cell as the box clipped by the
// bisectors to the Delaunay neighbours. std::invalid_argument for non-finite positions, R <= 0,
// an empty box or an agent outside it. Parallel over agents.
VoronoiCells voronoiCells(std::span<const Vec2f> positions, const VoronoiOptions& options = {});

// 1 / area(i) per agent [1/m^2].
std::vector<double> voronoiDensity(const VoronoiCells& cells);

// Density and speed in a measurement area M (Zhang et al. 2011, "Transitions in pedestrian
// fundamental diagrams of straight corridors and T-junctions", J. Stat. Mech. P06004):
//   rho_M = sum_i |A_i ∩ M| / (|A_i| |M|),   v_M = sum_i |A_i ∩ M| |v_i| / sum_i |A_i ∩ M|
// with A_i the clipped cell (shared by the agents at one position): an agent half inside M counts
// half. Where the cells cover M this v_M is Zhang's sum_i |A_i ∩ M| |v_i| / |M|; where they do not
// (clipped by R) it stays the mean speed of the people there instead of dropping towards 0.
struct AreaMeasurement {
  double area = 0.0;     // |M| [m^2]
  double density = 0.0;  // [1/m^2]
  double speed = 0.0;    // density-weighted mean speed over M [m/s]; 0 if nobody overlaps M
};
// M is a simple polygon in either orientation. velocities may be empty (speed stays 0), else one
// per cell. std::invalid_argument for a degenerate M or mismatched sizes.
AreaMeasurement measureArea(const VoronoiCells& cells, std::span<const Vec2f> velocities,
                            const Polygon& area);

// Exact area of a simple polygon ∩ the disc |x - centre| <= radius [m^2] (sum over edges of the
// signed areas of the triangle (centre, edge) ∩ disc; the orientation of the polygon does not
// matter).
double polygonDiscArea(const Polygon& polygon, const Vec2& centre, double radius);

// Clips a polygon to the half-plane {x : dot(normal, x) <= offset} (Sutherland & Hodgman 1974).
// A convex polygon stays convex; for a non-convex one the result may have zero-width bridges,
// which do not change its area.
Polygon clipHalfPlane(const Polygon& polygon, const Vec2& normal, double offset);

}  // namespace msim::crowd
