// Roadmap planner (Narain 2011 ch. 4.3.1). CGAL stays in this file: the triangulation is only
// needed while building; queries use the roadmap tables and two uniform grids.
#include "msim/crowd/roadmap/roadmap.hpp"

#include <algorithm>
#include <cmath>
#include <functional>
#include <limits>
#include <queue>
#include <string>
#include <tuple>
#include <utility>

#include <CGAL/Constrained_Delaunay_triangulation_2.h>
#include <CGAL/Exact_predicates_inexact_constructions_kernel.h>
#include <CGAL/Triangulation_face_base_with_info_2.h>
#include <fmt/format.h>
#include <tbb/parallel_for.h>

#include "msim/core/error.hpp"

namespace msim::crowd {
namespace {

constexpr float kInfF = std::numeric_limits<float>::infinity();
constexpr std::uint32_t kNone = std::numeric_limits<std::uint32_t>::max();

std::string str(const Vec2& v) { return fmt::format("({:g}, {:g})", v.x(), v.y()); }

// Per face: walkable or not, and the roadmap vertex on each of its three edges (kNone if the
// edge lies on an obstacle or the domain boundary).
struct FaceInfo {
  bool free = false;
  std::uint32_t edgeVertex[3] = {kNone, kNone, kNone};
};
using K = CGAL::Exact_predicates_inexact_constructions_kernel;
using Fb = CGAL::Triangulation_face_base_with_info_2<FaceInfo, K, CGAL::Constrained_triangulation_face_base_2<K>>;
using Tds = CGAL::Triangulation_data_structure_2<CGAL::Triangulation_vertex_base_2<K>, Fb>;
// Exact_predicates_tag: obstacles may overlap each other and the domain sides; CGAL then inserts
// the constraint intersections.
using Cdt = CGAL::Constrained_Delaunay_triangulation_2<K, Tds, CGAL::Exact_predicates_tag>;

Vec2 toVec(const K::Point_2& p) { return {p.x(), p.y()}; }

// Cells of a uniform grid over [lo, hi] holding item ids.
struct Buckets {
  Vec2 lo;
  double cell = 1;
  IVec2 n = IVec2::Ones();
  std::vector<std::vector<std::uint32_t>> items;

  Buckets(const Vec2& lo_, const Vec2& hi, double cellSize) : lo(lo_), cell(cellSize) {
    for (int d = 0; d < 2; ++d) n[d] = std::max(1, static_cast<int>(std::ceil((hi[d] - lo[d]) / cell)));
    items.resize(static_cast<std::size_t>(n[0]) * n[1]);
  }
  int coord(double x, int d) const { return std::clamp(static_cast<int>(std::floor((x - lo[d]) / cell)), 0, n[d] - 1); }
  std::vector<std::uint32_t>& at(int i, int j) { return items[static_cast<std::size_t>(j) * n[0] + i]; }
  const std::vector<std::uint32_t>& at(int i, int j) const { return items[static_cast<std::size_t>(j) * n[0] + i]; }
  // Insert into every cell the box [a, b] (slightly grown, so corner points land in all cells
  // sharing the corner) overlaps.
  void insertBox(const Vec2& a, const Vec2& b, std::uint32_t id) {
    const double eps = 1e-9 * cell;
    for (int j = coord(std::min(a.y(), b.y()) - eps, 1); j <= coord(std::max(a.y(), b.y()) + eps, 1); ++j)
      for (int i = coord(std::min(a.x(), b.x()) - eps, 0); i <= coord(std::max(a.x(), b.x()) + eps, 0); ++i) at(i, j).push_back(id);
  }
};

// Grid cell size giving about `perCell` items per cell over the box.
double cellFor(const Vec2& lo, const Vec2& hi, std::size_t count, double perCell) {
  const double area = (hi - lo).prod();
  return std::max(std::sqrt(area * perCell / std::max<std::size_t>(count, 1)), 1e-6 * (hi - lo).maxCoeff());
}

}  // namespace

struct Roadmap::EdgeGrid : Buckets {
  using Buckets::Buckets;
  std::vector<std::pair<Vec2, Vec2>> segments;
};

struct Roadmap::VertexGrid : Buckets {
  using Buckets::Buckets;
};

Roadmap::~Roadmap() = default;

Roadmap::Roadmap(std::vector<Goal> goals, std::vector<Polygon> obstacles, const RoadmapOptions& options)
    : goals_(std::move(goals)) {
  const Vec2 lo = options.lo, hi = options.hi;
  if (!lo.allFinite() || !hi.allFinite() || !((hi - lo).minCoeff() > 0))
    throw InputError(fmt::format("roadmap: empty or invalid domain {} .. {}", str(lo), str(hi)));
  std::vector<Vec2> boxLo, boxHi;
  for (std::size_t k = 0; k < obstacles.size(); ++k) {
    validateSimple(obstacles[k], fmt::format("obstacles[{}]", k));
    boxLo.emplace_back(), boxHi.emplace_back();
    bounds(obstacles[k], boxLo.back(), boxHi.back());
  }
  const auto inDomain = [&](const Vec2& x) { return (x.array() >= lo.array()).all() && (x.array() <= hi.array()).all(); };
  const auto insideObstacle = [&](const Vec2& x) {
    for (std::size_t k = 0; k < obstacles.size(); ++k)
      if ((x.array() >= boxLo[k].array()).all() && (x.array() <= boxHi[k].array()).all() && contains(obstacles[k], x))
        return static_cast<long>(k);
    return -1L;
  };

  // 1. Constrained Delaunay triangulation of the domain with the obstacle edges as constraints.
  Cdt cdt;
  const Vec2 corners[4] = {lo, {hi.x(), lo.y()}, hi, {lo.x(), hi.y()}};
  for (int c = 0; c < 4; ++c)
    cdt.insert_constraint(K::Point_2(corners[c].x(), corners[c].y()), K::Point_2(corners[(c + 1) % 4].x(), corners[(c + 1) % 4].y()));
  std::size_t obstacleEdges = 0;
  for (const Polygon& p : obstacles) {
    std::vector<K::Point_2> ring;
    for (const Vec2& v : p.vertices) ring.emplace_back(v.x(), v.y());
    cdt.insert_constraint(ring.begin(), ring.end(), true);
    obstacleEdges += p.size();
  }
  if (options.spacing > 0) {
    // Lattice points a quarter spacing or more off every obstacle, so no slivers hug the walls.
    const double s = options.spacing, margin = 0.25 * s;
    std::vector<K::Point_2> steiner;
    for (double y = lo.y() + 0.5 * s; y < hi.y(); y += s)
      for (double x = lo.x() + 0.5 * s; x < hi.x(); x += s) {
        const Vec2 p(x, y);
        bool clear = true;
        for (std::size_t k = 0; k < obstacles.size() && clear; ++k)
          clear = ((p.array() < boxLo[k].array() - margin).any() || (p.array() > boxHi[k].array() + margin).any() ||
                   signedDistance(obstacles[k], p) > margin);
        if (clear) steiner.emplace_back(x, y);
      }
    cdt.insert(steiner.begin(), steiner.end());
  }
  // A triangle is free if its centroid is in the domain and in no obstacle: constraints split the
  // plane along every obstacle edge, so the centroid decides for the whole triangle, also where
  // obstacles overlap (which defeats the nesting-level parity).
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    const Vec2 c = (toVec(f->vertex(0)->point()) + toVec(f->vertex(1)->point()) + toVec(f->vertex(2)->point())) / 3.0;
    f->info().free = inDomain(c) && insideObstacle(c) < 0;
  }

  // 2. Roadmap vertices at midpoints of free, unconstrained edges; edges within free triangles.
  for (auto e = cdt.finite_edges_begin(); e != cdt.finite_edges_end(); ++e) {
    const auto f = e->first;
    const int i = e->second;
    if (cdt.is_constrained(*e) || !f->info().free) continue;
    const auto g = f->neighbor(i);
    const auto id = static_cast<std::uint32_t>(positions_.size());
    positions_.push_back(0.5 * (toVec(f->vertex(cdt.cw(i))->point()) + toVec(f->vertex(cdt.ccw(i))->point())));
    f->info().edgeVertex[i] = id;
    g->info().edgeVertex[g->index(f)] = id;
  }
  midpointCount_ = positions_.size();
  const std::size_t vcount = midpointCount_ + goals_.size();
  if (vcount > options.maxVertices)
    throw InputError(fmt::format("roadmap: {} vertices exceed the limit of {} (Floyd-Warshall takes O(V^3) time and "
                                 "8 V^2 bytes = {:.0f} MB here); use the navigation field planner for this scene",
                                 vcount, options.maxVertices, 8.0 * vcount * vcount / 1e6));
  std::vector<std::tuple<std::uint32_t, std::uint32_t, float>> links;
  for (auto f = cdt.finite_faces_begin(); f != cdt.finite_faces_end(); ++f) {
    if (!f->info().free) continue;
    const auto* ev = f->info().edgeVertex;
    for (int a = 0; a < 3; ++a)
      for (int b = a + 1; b < 3; ++b)
        if (ev[a] != kNone && ev[b] != kNone) links.emplace_back(ev[a], ev[b], float((positions_[ev[a]] - positions_[ev[b]]).norm()));
  }

  // 3. Goal vertices. A point goal joins the vertices of its triangle (all visible: the triangle
  // is convex); a region goal sits at an interior point and joins, at zero cost, every roadmap
  // vertex inside the region, plus the vertices of the triangle holding that point.
  for (std::size_t g = 0; g < goals_.size(); ++g) {
    const Goal& goal = goals_[g];
    const auto gv = static_cast<std::uint32_t>(midpointCount_ + g);
    Vec2 anchor = goal.point;
    if (goal.kind == Goal::Kind::Region) {
      // A goal vertex stands at one place; a set of exits needs the navigation field's fronts.
      if (goal.regions.size() != 1)
        throw InputError(fmt::format("goals[{}]: the roadmap plans for goals of one region, this one has {}; use "
                                     "crowd.planner.type = 'navigation_field' for a set of exits",
                                     g, goal.regions.size()));
      const Polygon& region = goal.regions.front();
      validateSimple(region, fmt::format("goals[{}].region", g));
      // Fan-triangle centroids from vertex 0 until one lies inside (the first does if convex).
      anchor = Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
      for (std::size_t k = 1; k + 1 < region.size() && !anchor.allFinite(); ++k) {
        const Vec2 c = (region.vertex(0) + region.vertex(k) + region.vertex(k + 1)) / 3.0;
        if (contains(region, c)) anchor = c;
      }
      for (std::uint32_t v = 0; v < midpointCount_; ++v)
        if (contains(region, positions_[v])) links.emplace_back(v, gv, 0.0f);
    }
    positions_.push_back(anchor);
    const std::string what = goal.kind == Goal::Kind::Point ? fmt::format("goals[{}]: point {}", g, str(anchor))
                                                            : fmt::format("goals[{}].region: interior point {}", g, str(anchor));
    if (!anchor.allFinite() || !inDomain(anchor))
      throw InputError(fmt::format("{} lies outside the planning domain {} .. {}", what, str(lo), str(hi)));
    if (const long k = insideObstacle(anchor); k >= 0) throw InputError(fmt::format("{} lies inside obstacles[{}]", what, k));
    const auto f = cdt.locate(K::Point_2(anchor.x(), anchor.y()));
    if (cdt.is_infinite(f) || !f->info().free) throw InputError(fmt::format("{} is not in walkable space", what));
    for (std::uint32_t v : f->info().edgeVertex)
      if (v != kNone) links.emplace_back(v, gv, float((positions_[v] - anchor).norm()));
  }
  edgeCount_ = links.size();

  // 4. Floyd-Warshall with next-hop table. For a fixed k row k does not change (d[k][k] = 0), so
  // rows i are independent and run in parallel.
  const std::size_t nv = positions_.size();
  dist_.assign(nv * nv, kInfF);
  next_.assign(nv * nv, kNone);
  for (std::size_t v = 0; v < nv; ++v) dist_[v * nv + v] = 0, next_[v * nv + v] = static_cast<std::uint32_t>(v);
  for (const auto& [a, b, w] : links)
    if (w < dist_[a * nv + b]) {
      dist_[a * nv + b] = dist_[b * nv + a] = w;
      next_[a * nv + b] = b, next_[b * nv + a] = a;
    }
  for (std::size_t k = 0; k < nv; ++k) {
    const float* dk = &dist_[k * nv];
    tbb::parallel_for(tbb::blocked_range<std::size_t>(0, nv, 16), [&](const tbb::blocked_range<std::size_t>& r) {
      for (std::size_t i = r.begin(); i != r.end(); ++i) {
        float* di = &dist_[i * nv];
        const float dik = di[k];
        if (dik == kInfF) continue;
        std::uint32_t* ni = &next_[i * nv];
        const std::uint32_t nik = ni[k];
        for (std::size_t j = 0; j < nv; ++j)
          if (dik + dk[j] < di[j]) di[j] = dik + dk[j], ni[j] = nik;
      }
    });
  }

  // 5. Query accelerators: obstacle edges and roadmap midpoints bucketed on uniform grids.
  edges_ = std::make_unique<EdgeGrid>(lo, hi, cellFor(lo, hi, obstacleEdges, 2.0));
  for (const Polygon& p : obstacles)
    for (std::size_t i = 0; i < p.size(); ++i) {
      edges_->insertBox(p.vertex(i), p.vertex(i + 1), static_cast<std::uint32_t>(edges_->segments.size()));
      edges_->segments.emplace_back(p.vertex(i), p.vertex(i + 1));
    }
  vertices_ = std::make_unique<VertexGrid>(lo, hi, cellFor(lo, hi, midpointCount_, 4.0));
  for (std::uint32_t v = 0; v < midpointCount_; ++v) vertices_->insertBox(positions_[v], positions_[v], v);
}

bool Roadmap::visible(const Vec2& a, const Vec2& b) const {
  // Amanatides-Woo walk through the edge grid cells the segment crosses.
  const Buckets& grid = *edges_;
  const Vec2 ga = (a - grid.lo) / grid.cell, gb = (b - grid.lo) / grid.cell, d = gb - ga;
  int c[2], last[2], step[2];
  double tMax[2], tDelta[2];
  for (int k = 0; k < 2; ++k) {
    c[k] = grid.coord(a[k], k), last[k] = grid.coord(b[k], k);
    step[k] = d[k] > 0 ? 1 : -1;
    tDelta[k] = d[k] != 0 ? 1.0 / std::abs(d[k]) : std::numeric_limits<double>::infinity();
    tMax[k] = d[k] != 0 ? ((c[k] + (d[k] > 0 ? 1 : 0)) - ga[k]) / d[k] : std::numeric_limits<double>::infinity();
  }
  for (int guard = grid.n[0] + grid.n[1] + 2; guard-- > 0;) {
    for (std::uint32_t e : grid.at(c[0], c[1])) {
      const auto& [p, q] = edges_->segments[e];
      if (segmentsIntersect(a, b, p, q)) return false;
    }
    if (c[0] == last[0] && c[1] == last[1]) break;
    const int k = tMax[0] < tMax[1] ? 0 : 1;
    if (tMax[k] > 1) break;
    c[k] += step[k], tMax[k] += tDelta[k];
    if (c[k] < 0 || c[k] >= grid.n[k]) break;
  }
  return true;
}

std::uint32_t Roadmap::nearestVisible(const Vec2& x) const {
  // Rings of cells outwards; a candidate at distance <= r * cell after ring r is nearer than any
  // unseen vertex, so candidates are tested for visibility in distance order.
  const VertexGrid& grid = *vertices_;
  using Entry = std::pair<double, std::uint32_t>;
  std::priority_queue<Entry, std::vector<Entry>, std::greater<>> candidates;
  const int ci = grid.coord(x.x(), 0), cj = grid.coord(x.y(), 1);
  std::uint32_t nearest = kNone;
  const auto drain = [&](double bound) {
    while (!candidates.empty() && candidates.top().first <= bound) {
      const std::uint32_t v = candidates.top().second;
      candidates.pop();
      if (nearest == kNone) nearest = v;
      if (visible(x, positions_[v])) return v;
    }
    return kNone;
  };
  const int rings = std::max(grid.n[0], grid.n[1]);
  for (int r = 0; r <= rings; ++r) {
    for (int j = cj - r; j <= cj + r; ++j)
      for (int i = ci - r; i <= ci + r; ++i) {
        if (std::max(std::abs(i - ci), std::abs(j - cj)) != r || i < 0 || j < 0 || i >= grid.n[0] || j >= grid.n[1]) continue;
        for (std::uint32_t v : grid.at(i, j)) candidates.emplace((positions_[v] - x).norm(), v);
      }
    if (const std::uint32_t v = drain(r * grid.cell); v != kNone) return v;
  }
  if (const std::uint32_t v = drain(std::numeric_limits<double>::infinity()); v != kNone) return v;
  return nearest;  // nothing visible (the agent is inside an obstacle): the nearest vertex
}

Roadmap::Route Roadmap::route(std::size_t goal, const Vec2& position) const {
  const Goal& g = goals_.at(goal);
  const auto gv = static_cast<std::uint32_t>(midpointCount_ + goal);
  Route out;
  if (g.kind == Goal::Kind::Point && visible(position, g.point)) {
    out.path = {gv};
    return out;
  }
  const std::uint32_t start = midpointCount_ > 0 ? nearestVisible(position) : kNone;
  if (start == kNone || pathLength(start, gv) == kInfF) return out;
  const std::size_t nv = positions_.size();
  for (std::uint32_t v = start; v != gv; v = next_[v * nv + gv]) out.path.push_back(v);
  out.path.push_back(gv);
  // The seed's sub-goal: the visible path vertex closest to the goal.
  for (std::size_t k = out.path.size(); k-- > 1;)
    if (visible(position, positions_[out.path[k]])) {
      out.target = k;
      break;
    }
  return out;
}

double Roadmap::distance(std::size_t goal, const Vec2& position) const {
  if (goals_.at(goal).kind == Goal::Kind::Region && goals_[goal].reached(position)) return 0.0;
  const Route r = route(goal, position);
  if (r.path.empty()) return std::numeric_limits<double>::infinity();
  const std::uint32_t t = r.path[r.target];
  return (positions_[t] - position).norm() + pathLength(t, static_cast<std::uint32_t>(midpointCount_ + goal));
}

bool Roadmap::reachable(std::size_t goal, const Vec2& position) const {
  return std::isfinite(distance(goal, position));
}

Vec2 Roadmap::direction(std::size_t goal, const Vec2& position) const {
  if (goals_.at(goal).reached(position)) return Vec2::Zero();
  const Route r = route(goal, position);
  // Standing on the sub-goal itself: head for the one after it.
  for (std::size_t k = r.target; k < r.path.size(); ++k) {
    const Vec2 d = positions_[r.path[k]] - position;
    if (d.norm() > 1e-9) return d.normalized();
  }
  return Vec2::Zero();
}

}  // namespace msim::crowd
