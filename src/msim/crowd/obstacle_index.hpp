#pragma once
// Static obstacle polygons indexed for the per-agent passes (collision resolution, ORCA, inflow
// placement): many concurrent queries of "which edges are near this point" and "where must a disc
// go to clear every obstacle".
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/rng.hpp"
#include "msim/crowd/agents.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

// Static obstacle polygons prepared for many concurrent per-agent queries: float copies of the
// polygons, and a uniform grid listing in each cell the obstacles whose bounds, grown by `reach`,
// overlap it, so a query only looks at the obstacles near the agent. Immutable after construction.
class StaticObstacles {
 public:
  StaticObstacles() = default;
  // reach: the largest query radius that will be used (an agent radius for pushOut, ORCA's
  // obstacle range for forEachEdgeNear).
  StaticObstacles(std::span<const Polygon> polygons, float reach);

  bool empty() const { return bounds_.empty(); }
  float reach() const { return reach_; }

  // Where a disc of the radius centred at p has to go to lie outside every obstacle with at least
  // `radius` between its centre and the boundary (p itself when it already does). Deep points go
  // out through the closest edge. radius <= reach.
  Vec2f pushOut(Vec2f p, float radius) const;
  // f(a, b) for each edge [a, b] of every obstacle whose bounds grown by reach contain p: a
  // superset of the edges within reach of p (callers test the distance).
  template <typename F>
  void forEachEdgeNear(const Vec2f& p, F&& f) const;

 private:
  struct Box {
    Vec2f lo, hi;
  };
  std::span<const std::uint32_t> candidates(const Vec2f& p) const;

  float reach_ = 0.0f;
  std::vector<Vec2f> vertices_;              // all polygons, concatenated
  std::vector<std::uint32_t> polygonStart_;  // polygon k: vertices_[polygonStart_[k], [k+1])
  std::vector<Box> bounds_;                  // grown by reach
  Vec2f origin_ = Vec2f::Zero();
  float cellSize_ = 1.0f;
  int nx_ = 0, ny_ = 0;
  std::vector<std::uint32_t> cellStart_;  // obstacles of cell c: cellObstacles_[cellStart_[c], [c+1])
  std::vector<std::uint32_t> cellObstacles_;
};

template <typename F>
void StaticObstacles::forEachEdgeNear(const Vec2f& p, F&& f) const {
  for (std::uint32_t k : candidates(p)) {
    const Box& b = bounds_[k];
    if (p.x() < b.lo.x() || p.y() < b.lo.y() || p.x() > b.hi.x() || p.y() > b.hi.y()) continue;
    const std::uint32_t begin = polygonStart_[k], end = polygonStart_[k + 1];
    for (std::uint32_t v = begin; v < end; ++v) f(vertices_[v], vertices_[v + 1 < end ? v + 1 : begin]);
  }
}

// A uniformly random point of `region` where a disc of the radius clears every obstacle of the
// index (radius <= its reach), by rejection from the region's bounds; NaN if `attempts` tries find
// none (the region lies inside obstacles). Places groups at the start and inflow agents later.
Vec2 randomFreePoint(Rng& rng, const Polygon& region, float radius, const StaticObstacles& obstacles,
                     int attempts = 100000);

}  // namespace msim::crowd
