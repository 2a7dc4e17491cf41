#include "msim/crowd/obstacle_index.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

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

Vec2 randomFreePoint(Rng& rng, const Polygon& region, float radius, const StaticObstacles& obstacles, int attempts) {
  Vec2 lo, hi;
  bounds(region, lo, hi);
  for (int attempt = 0; attempt < attempts; ++attempt) {
    const Vec2 x(rng.uniform(lo.x(), hi.x()), rng.uniform(lo.y(), hi.y()));
    const Vec2f xf = x.cast<float>();
    if (contains(region, x) && (obstacles.empty() || obstacles.pushOut(xf, radius) == xf)) return x;
  }
  return Vec2::Constant(std::numeric_limits<double>::quiet_NaN());
}

}  // namespace msim::crowd
