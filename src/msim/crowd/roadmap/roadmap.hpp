#pragma once
// Roadmap global planner, the algorithm of Narain 2011 ch. 4.3.1: a constrained Delaunay
// triangulation of the free space (obstacle edges as constraints); roadmap vertices at the
// midpoints of triangle edges not on an obstacle, joined when they share a free triangle;
// all-pairs shortest paths by Floyd-Warshall; an agent walks towards the visible sub-goal
// closest to the goal on the path between the roadmap vertices nearest to it and to the goal.
//
// Cost: Floyd-Warshall is O(V^3) time and the distance + next-hop tables O(V^2) memory
// (8 bytes per vertex pair: 800 MB at 10k vertices), so roadmaps larger than
// RoadmapOptions::maxVertices are refused; use the NavigationField for big scenes.
// Agents are treated as points (no clearance): the midpoints of free edges keep paths away from
// walls in practice, and the local avoidance keeps bodies out of obstacles.
#include <cstddef>
#include <cstdint>
#include <memory>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/goal.hpp"
#include "msim/crowd/planner.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

struct RoadmapOptions {
  Vec2 lo = Vec2::Zero();  // walkable domain [m]; its sides are walls
  Vec2 hi = Vec2::Zero();
  std::size_t maxVertices = 10000;  // refuse larger roadmaps (see above)
  // Steiner points on a square lattice of this spacing in free space [m] (0: none, the bare
  // triangulation of the obstacle vertices). The bare triangulation of a sparse scene has triangles
  // as large as the gaps between obstacles, and paths through their edge midpoints detour far from
  // the geodesic (+72 % round a 4 m square in a 20 m box); bounding the triangle size bounds the
  // detour. Cost: about 3 roadmap vertices per lattice point.
  double spacing = 2.0;
};

class Roadmap final : public GlobalPlanner {
 public:
  // Throws InputError naming the goal or obstacle for an invalid obstacle polygon, a goal outside
  // the domain or inside an obstacle, and for a roadmap of more than maxVertices vertices.
  Roadmap(std::vector<Goal> goals, std::vector<Polygon> obstacles, const RoadmapOptions& options);
  ~Roadmap() override;

  std::size_t goalCount() const override { return goals_.size(); }
  Vec2 direction(std::size_t goal, const Vec2& position) const override;
  double distance(std::size_t goal, const Vec2& position) const override;
  bool reachable(std::size_t goal, const Vec2& position) const;

  // Roadmap vertices (edge midpoints, then one vertex per goal) and undirected edges.
  std::size_t vertexCount() const { return positions_.size(); }
  std::size_t edgeCount() const { return edgeCount_; }
  // Planned route for an agent: the roadmap path from its nearest visible vertex to the goal,
  // `target` the index in it of the visible sub-goal closest to the goal; empty if unreachable.
  struct Route {
    std::vector<std::uint32_t> path;
    std::size_t target = 0;
  };
  Route route(std::size_t goal, const Vec2& position) const;
  const Vec2& vertex(std::uint32_t v) const { return positions_[v]; }

 private:
  // Does the segment (a, b) cross an obstacle edge? Walks a uniform grid of obstacle edges.
  bool visible(const Vec2& a, const Vec2& b) const;
  // Nearest roadmap vertex (not a goal vertex) visible from x, or nearest at all if none is.
  std::uint32_t nearestVisible(const Vec2& x) const;
  float pathLength(std::uint32_t from, std::uint32_t to) const { return dist_[from * positions_.size() + to]; }

  struct EdgeGrid;     // obstacle edges bucketed by cell
  struct VertexGrid;   // roadmap vertices bucketed by cell
  std::vector<Goal> goals_;
  std::vector<Vec2> positions_;      // midpoints, then goal vertices (goal g is midpointCount_ + g)
  std::size_t midpointCount_ = 0;
  std::size_t edgeCount_ = 0;
  std::vector<float> dist_;          // V x V shortest path lengths, +inf if disconnected
  std::vector<std::uint32_t> next_;  // V x V first hop on the shortest path
  std::unique_ptr<EdgeGrid> edges_;
  std::unique_ptr<VertexGrid> vertices_;
};

}  // namespace msim::crowd
