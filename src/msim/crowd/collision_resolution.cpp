#include "msim/crowd/collision_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"

namespace msim::crowd {

namespace {

// Cells per side of the obstacle grid at most: bounds the memory for large polygons that are
// listed in every cell they cover.
constexpr float kObstacleGridCells = 128.0f;

Vec2f closestOnSegment(const Vec2f& a, const Vec2f& b, const Vec2f& p) {
  const Vec2f d = b - a;
  const float len2 = d.squaredNorm();
  const float t = len2 > 0.0f ? std::clamp((p - a).dot(d) / len2, 0.0f, 1.0f) : 0.0f;
  return a + t * d;
}

// Unit direction pushing i away from j when they coincide: a direction hashed from the pair, with
// opposite signs for i and j, so the pushes still cancel and the result stays deterministic.
Vec2f coincidentDirection(std::size_t i, std::size_t j) {
  const std::uint64_t lo = std::min(i, j), hi = std::max(i, j);
  std::uint64_t h = lo * 0x9E3779B97F4A7C15ull ^ (hi + 0x632BE59BD9B4E019ull);
  h ^= h >> 31;
  h *= 0xD6E8FEB86659FD93ull;
  h ^= h >> 32;
  const float angle = static_cast<float>(h & 0xFFFFFF) * (6.2831853f / 16777216.0f);
  const float sign = i < j ? 1.0f : -1.0f;
  return sign * Vec2f(std::cos(angle), std::sin(angle));
}

}  // namespace

StaticObstacles::StaticObstacles(std::span<const Polygon> polygons, float reach) : reach_(reach) {
  if (polygons.empty()) return;
  polygonStart_.push_back(0);
  Vec2f lo = Vec2f::Constant(std::numeric_limits<float>::max());
  Vec2f hi = Vec2f::Constant(std::numeric_limits<float>::lowest());
  for (const Polygon& poly : polygons) {
    Box box{Vec2f::Constant(std::numeric_limits<float>::max()), Vec2f::Constant(std::numeric_limits<float>::lowest())};
    for (const Vec2& v : poly.vertices) {
      vertices_.push_back(v.cast<float>());
      box.lo = box.lo.cwiseMin(vertices_.back());
      box.hi = box.hi.cwiseMax(vertices_.back());
    }
    polygonStart_.push_back(static_cast<std::uint32_t>(vertices_.size()));
    box.lo.array() -= reach;
    box.hi.array() += reach;
    bounds_.push_back(box);
    lo = lo.cwiseMin(box.lo);
    hi = hi.cwiseMax(box.hi);
  }
  origin_ = lo;
  const Vec2f extent = hi - lo;
  cellSize_ = std::max({reach, extent.maxCoeff() / kObstacleGridCells, 1e-3f});
  nx_ = static_cast<int>(std::floor(extent.x() / cellSize_)) + 1;
  ny_ = static_cast<int>(std::floor(extent.y() / cellSize_)) + 1;
  auto cellRange = [&](const Box& b, int& i0, int& i1, int& j0, int& j1) {
    i0 = std::clamp(static_cast<int>(std::floor((b.lo.x() - origin_.x()) / cellSize_)), 0, nx_ - 1);
    i1 = std::clamp(static_cast<int>(std::floor((b.hi.x() - origin_.x()) / cellSize_)), 0, nx_ - 1);
    j0 = std::clamp(static_cast<int>(std::floor((b.lo.y() - origin_.y()) / cellSize_)), 0, ny_ - 1);
    j1 = std::clamp(static_cast<int>(std::floor((b.hi.y() - origin_.y()) / cellSize_)), 0, ny_ - 1);
  };
  // Counting sort of (cell, obstacle) pairs, obstacles in input order within a cell.
  cellStart_.assign(static_cast<std::size_t>(nx_) * ny_ + 1, 0);
  int i0, i1, j0, j1;
  for (const Box& b : bounds_) {
    cellRange(b, i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) ++cellStart_[static_cast<std::size_t>(j) * nx_ + i + 1];
  }
  for (std::size_t c = 1; c < cellStart_.size(); ++c) cellStart_[c] += cellStart_[c - 1];
  cellObstacles_.resize(cellStart_.back());
  std::vector<std::uint32_t> fill(cellStart_.begin(), cellStart_.end() - 1);
  for (std::uint32_t k = 0; k < bounds_.size(); ++k) {
    cellRange(bounds_[k], i0, i1, j0, j1);
    for (int j = j0; j <= j1; ++j)
      for (int i = i0; i <= i1; ++i) cellObstacles_[fill[static_cast<std::size_t>(j) * nx_ + i]++] = k;
  }
}

std::span<const std::uint32_t> StaticObstacles::candidates(const Vec2f& p) const {
  if (nx_ == 0) return {};
  const Vec2f rel = (p - origin_) / cellSize_;
  const int i = static_cast<int>(std::floor(rel.x())), j = static_cast<int>(std::floor(rel.y()));
  if (i < 0 || j < 0 || i >= nx_ || j >= ny_) return {};
  const std::size_t c = static_cast<std::size_t>(j) * nx_ + i;
  return std::span<const std::uint32_t>(cellObstacles_).subspan(cellStart_[c], cellStart_[c + 1] - cellStart_[c]);
}

Vec2f StaticObstacles::pushOut(Vec2f p, float radius) const {
  for (std::uint32_t k : candidates(p)) {
    const Box& b = bounds_[k];
    if (p.x() < b.lo.x() || p.y() < b.lo.y() || p.x() > b.hi.x() || p.y() > b.hi.y()) continue;
    // One pass over the edges: closest boundary point, and the even-odd crossing count of a ray
    // towards +x for the inside test.
    const std::uint32_t begin = polygonStart_[k], end = polygonStart_[k + 1];
    float best = std::numeric_limits<float>::max();
    Vec2f closest = p, edgeDir = Vec2f::UnitX();
    bool inside = false;
    float twiceArea = 0.0f;
    for (std::uint32_t v = begin; v < end; ++v) {
      const Vec2f& a = vertices_[v];
      const Vec2f& c = vertices_[v + 1 < end ? v + 1 : begin];
      twiceArea += a.x() * c.y() - c.x() * a.y();
      if ((a.y() > p.y()) != (c.y() > p.y()) &&
          p.x() < a.x() + (p.y() - a.y()) * (c.x() - a.x()) / (c.y() - a.y()))
        inside = !inside;
      const Vec2f q = closestOnSegment(a, c, p);
      const float d2 = (q - p).squaredNorm();
      if (d2 < best) {
        best = d2;
        closest = q;
        edgeDir = c - a;
      }
    }
    const float dist = std::sqrt(best);
    if (!inside && dist >= radius) continue;
    // Away from the obstacle: from the boundary point to p outside, from p to it inside; for a
    // point on the boundary, the outward normal of its edge (right of a counter-clockwise edge).
    Vec2f out;
    if (dist > 1e-6f * std::max(1.0f, radius)) {
      out = (inside ? closest - p : p - closest) / dist;
    } else {
      out = Vec2f(edgeDir.y(), -edgeDir.x()).normalized();
      if (twiceArea < 0.0f) out = -out;
    }
    p = closest + radius * out;
  }
  return p;
}

void CollisionResolver::bucket(std::span<const Vec2f> position, const Agents& agents, float cellSize) {
  grid_.build(position, cellSize);
  ++bucketings_;
  const std::size_t n = position.size();
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  const std::span<const Vec2f> sorted = grid_.sortedPoints();
  current_.resize(n);
  next_.resize(n);
  bucketed_.resize(n);
  radius_.resize(n);
  scripted_.resize(n);
  const std::size_t cells = static_cast<std::size_t>(grid_.cellsX()) * grid_.cellsY();
  moved_.resize(cells);
  movedNext_.resize(cells);
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t i = order[k];
        current_[k] = bucketed_[k] = sorted[k];
        radius_[k] = agents.radius[i];
        scripted_[k] = agents.model[i] == AgentModel::Scripted ? 1 : 0;
      },
      4096);
}

void CollisionResolver::resolve(Agents& agents, const StaticObstacles& obstacles, const DomainBox& domain,
                                const CollisionResolutionParams& params) {
  bucketings_ = 0;
  const std::size_t n = agents.size();
  if (n == 0 || params.iterations <= 0) return;
  const float s = params.separation;
  const float rmax = static_cast<float>(parallelMax(n, [&](std::size_t i) { return agents.radius[i]; }));
  if (!(rmax > 0.0f)) return;
  // Interaction range: no pair farther apart than this is pushed. The cells get a skin on top, so
  // agents may move a little before the buckets have to be redone.
  const float range = s * 2.0f * rmax;
  constexpr float kSkin = 0.3f;
  bucket(agents.position, agents, range * (1.0f + kSkin));
  int bucketedAt = 0;         // the first sweep on the current buckets
  float movedSinceBucket2 = 0;  // largest squared displacement since then

  for (int it = 0; it < params.iterations; ++it) {
    const int nx = grid_.cellsX(), ny = grid_.cellsY();
    const std::span<const std::uint32_t> order = grid_.cellOrder();
    const Vec2f* cur = current_.data();
    Vec2f* next = next_.data();
    const Vec2f* bucketed = bucketed_.data();
    const float* rad = radius_.data();
    const std::uint8_t* scripted = scripted_.data();
    const std::uint8_t* moved = moved_.data();
    std::uint8_t* movedNext = movedNext_.data();
    const bool everything = it == bucketedAt;  // no earlier sweep on these buckets to compare with

    // The agents of one cell: next from cur. Their neighbours are the three contiguous slot ranges
    // of the stencil. worst: the largest squared displacement since bucketing of those that move.
    auto sweepCell = [&](std::uint32_t first, std::uint32_t last, const NeighbourGrid::Stencil& st, float& worst) {
      // Nothing in the stencil moved in the last sweep: its agents' inputs are those of that
      // sweep, in which they did not move, so they do not move now (skipping is exact).
      if (!everything) {
        bool dirty = false;
        for (int cy = st.y0; cy <= st.y1; ++cy)
          for (int cx = st.x0; cx <= st.x1; ++cx) dirty |= moved[static_cast<std::size_t>(cy) * nx + cx] != 0;
        if (!dirty) {
          std::copy(cur + first, cur + last, next + first);
          movedNext[st.cell] = 0;
          return;
        }
      }
      std::uint8_t cellMoved = 0;
      for (std::uint32_t k = first; k < last; ++k) {
        const Vec2f xi = cur[k];
        next[k] = xi;
        if (scripted[k]) continue;
        const float ri = rad[k];
        float dx = 0.0f, dy = 0.0f;
        for (int q = 0; q < st.count; ++q) {
          for (std::uint32_t j = st.lo[q]; j < st.hi[q]; ++j) {
            const float ex = xi.x() - cur[j].x(), ey = xi.y() - cur[j].y();
            const float target = s * (ri + rad[j]);
            const float d2 = ex * ex + ey * ey;
            if (d2 >= target * target || j == k) continue;
            const float dist = std::sqrt(d2);
            // Symmetric halves; a scripted agent does not yield, so i takes all of it.
            const float push = (scripted[j] ? 1.0f : 0.5f) * (target - dist);
            if (dist > 1e-7f * target) {
              dx += push * (ex / dist);
              dy += push * (ey / dist);
            } else {
              const Vec2f dir = coincidentDirection(order[k], order[j]);
              dx += push * dir.x();
              dy += push * dir.y();
            }
          }
        }
        Vec2f x(xi.x() + dx, xi.y() + dy);
        if (!obstacles.empty()) x = obstacles.pushOut(x, ri);
        for (int a = 0; a < 2; ++a) {
          const float lo = domain.lo[a] + ri, hi = domain.hi[a] - ri;
          x[a] = lo <= hi ? std::clamp(x[a], lo, hi) : 0.5f * (domain.lo[a] + domain.hi[a]);
        }
        if (x == xi) continue;
        next[k] = x;
        cellMoved = 1;
        worst = std::max(worst, (x - bucketed[k]).squaredNorm());
      }
      movedNext[st.cell] = cellMoved;
    };

    // Rows of cells per task: about 2048 agents. The max does not depend on how tasks combine.
    const std::size_t grain = std::max<std::size_t>(1, static_cast<std::size_t>(ny) * 2048 / n);
    const float moved2 = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, ny, grain), 0.0f,
        [&](const tbb::blocked_range<int>& rows, float worst) {
          grid_.forEachCellInRows(rows.begin(), rows.end(),
                                  [&](std::uint32_t first, std::uint32_t last, const NeighbourGrid::Stencil& st) {
                                    sweepCell(first, last, st, worst);
                                  });
          return worst;
        },
        [](float a, float b) { return std::max(a, b); });
    current_.swap(next_);
    moved_.swap(movedNext_);
    if (it + 1 == params.iterations) break;
    // A pair within range now was within range + 2 * max displacement when bucketed: still in
    // each other's stencil while that fits in a cell (with a margin for round-off). Otherwise the
    // agents are bucketed again where they are now.
    // (An agent that did not move in a sweep has the displacement of the last sweep it moved in.)
    movedSinceBucket2 = std::max(movedSinceBucket2, moved2);
    if (range + 2.0f * std::sqrt(movedSinceBucket2) * 1.001f + 1e-6f * range >= grid_.cellSize()) {
      const std::span<const std::uint32_t> ord = grid_.cellOrder();
      parallelFor(
          0, n, [&](std::size_t k) { agents.position[ord[k]] = current_[k]; }, 4096);
      bucket(agents.position, agents, range * (1.0f + kSkin));
      bucketedAt = it + 1;
      movedSinceBucket2 = 0.0f;
    }
  }
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  parallelFor(
      0, n, [&](std::size_t k) { agents.position[order[k]] = current_[k]; }, 4096);
}

}  // namespace msim::crowd
