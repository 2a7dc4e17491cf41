#include "msim/crowd/collision_resolution.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

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

constexpr std::size_t kPad = 8;

void CollisionResolver::bucket(const Agents& agents, float cellSize) {
  grid_.build(agents.position, cellSize);
  ++bucketings_;
  const std::size_t n = agents.size();
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  const std::span<const Vec2f> sorted = grid_.sortedPoints();
  // Padding: far away (the squared distance overflows to inf), so never within range.
  for (auto* v : {&x_, &y_, &nextX_, &nextY_}) v->resize(n + kPad, 1e30f);
  for (auto* v : {&radius_, &yield_, &tmpRadius_, &tmpYield_}) v->resize(n + kPad, 0.0f);
  bucketed_.resize(n);
  scripted_.resize(n);
  agent_.resize(n);
  resizeCellFlags();
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t i = order[k];
        agent_[k] = i;
        bucketed_[k] = sorted[k];
        x_[k] = sorted[k].x();
        y_[k] = sorted[k].y();
        radius_[k] = agents.radius[i];
        scripted_[k] = agents.model[i] == AgentModel::Scripted ? 1 : 0;
        yield_[k] = scripted_[k] ? 1.0f : 0.5f;
      },
      4096);
}

void CollisionResolver::resizeCellFlags() {
  const std::size_t cells = static_cast<std::size_t>(grid_.cellsX()) * grid_.cellsY();
  moved_.resize(cells);
  movedNext_.resize(cells);
}

void CollisionResolver::rebucket(float cellSize) {
  // The slots are already roughly in cell order, so re-sorting them reads nearby memory, unlike
  // a gather from the agents (age order).
  const std::size_t n = agent_.size();
  points_.resize(n);
  parallelFor(
      0, n, [&](std::size_t k) { points_[k] = Vec2f(x_[k], y_[k]); }, 4096);
  grid_.build(points_, cellSize);
  ++bucketings_;
  const std::span<const std::uint32_t> from = grid_.cellOrder();
  const std::span<const Vec2f> sorted = grid_.sortedPoints();
  tmpScripted_.resize(n);
  tmpAgent_.resize(n);
  resizeCellFlags();
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t old = from[k];
        bucketed_[k] = sorted[k];
        x_[k] = sorted[k].x();
        y_[k] = sorted[k].y();
        tmpRadius_[k] = radius_[old];
        tmpYield_[k] = yield_[old];
        tmpScripted_[k] = scripted_[old];
        tmpAgent_[k] = agent_[old];
      },
      4096);
  radius_.swap(tmpRadius_);
  yield_.swap(tmpYield_);
  scripted_.swap(tmpScripted_);
  agent_.swap(tmpAgent_);
}

namespace {

// Sum over j in [lo, hi), j != k, of the push on agent k (at xi, radius ri) from agent j:
// yield[j] * (target - dist) along (x_i - x_j) / dist for pairs closer than target = s (r_i + r_j).
// Pairs closer than 1e-7 target (coincident) are counted in `coincident`, not pushed. The same
// arithmetic for (k, j) and (j, k) up to the sign of the difference: pushes are equal and opposite.
inline void pushScalar(const float* xs, const float* ys, const float* rad, const float* yield, std::uint32_t lo,
                       std::uint32_t hi, std::uint32_t k, float xi, float yi, float ri, float s, float& dx, float& dy,
                       int& coincident) {
  for (std::uint32_t j = lo; j < hi; ++j) {
    const float ex = xi - xs[j], ey = yi - ys[j];
    const float target = s * (ri + rad[j]);
    const float d2 = ex * ex + ey * ey;
    const float t2 = target * target;
    if (d2 >= t2 || j == k) continue;
    if (!(d2 > 1e-14f * t2)) {
      ++coincident;
      continue;
    }
    const float dist = std::sqrt(d2);
    const float f = yield[j] * (target - dist) / dist;
    dx += f * ex;
    dy += f * ey;
  }
}

#if defined(__AVX2__)
// pushScalar, eight neighbours at a time (reads up to 7 slots past hi, masked off).
inline void pushAvx(const float* xs, const float* ys, const float* rad, const float* yield, std::uint32_t lo,
                    std::uint32_t hi, std::uint32_t k, float xi, float yi, float ri, float s, __m256& ax, __m256& ay,
                    int& close) {
  const __m256 xv = _mm256_set1_ps(xi), yv = _mm256_set1_ps(yi), rv = _mm256_set1_ps(ri), sv = _mm256_set1_ps(s);
  const __m256 eps = _mm256_set1_ps(1e-14f);
  const __m256i hiv = _mm256_set1_epi32(static_cast<int>(hi)), kv = _mm256_set1_epi32(static_cast<int>(k));
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  for (std::uint32_t j = lo; j < hi; j += 8) {
    // Lanes in range, other than k itself.
    const __m256i idx = _mm256_add_epi32(_mm256_set1_epi32(static_cast<int>(j)), lane);
    const __m256 valid = _mm256_castsi256_ps(
        _mm256_andnot_si256(_mm256_cmpeq_epi32(idx, kv), _mm256_cmpgt_epi32(hiv, idx)));
    const __m256 ex = _mm256_sub_ps(xv, _mm256_loadu_ps(xs + j));
    const __m256 ey = _mm256_sub_ps(yv, _mm256_loadu_ps(ys + j));
    const __m256 d2 = _mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey));
    const __m256 target = _mm256_mul_ps(sv, _mm256_add_ps(rv, _mm256_loadu_ps(rad + j)));
    const __m256 t2 = _mm256_mul_ps(target, target);
    const __m256 in = _mm256_and_ps(valid, _mm256_cmp_ps(d2, t2, _CMP_LT_OQ));
    if (_mm256_testz_ps(in, in)) continue;
    const __m256 apart = _mm256_cmp_ps(d2, _mm256_mul_ps(eps, t2), _CMP_GT_OQ);
    close += __builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(_mm256_andnot_ps(apart, in))));
    // yield (target - dist) / dist = yield (target / dist - 1), with 1 / dist from the hardware
    // estimate and one Newton step (relative error ~1e-7, a third of the cost of sqrt + div). The
    // pair's two lanes see the same d2, so their pushes stay exactly equal and opposite.
    const __m256 est = _mm256_rsqrt_ps(d2);
    const __m256 inv = _mm256_mul_ps(
        _mm256_mul_ps(_mm256_set1_ps(0.5f), est),
        _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_mul_ps(d2, est), est)));
    const __m256 f =
        _mm256_mul_ps(_mm256_loadu_ps(yield + j), _mm256_sub_ps(_mm256_mul_ps(target, inv), _mm256_set1_ps(1.0f)));
    const __m256 m = _mm256_and_ps(in, apart);
    ax = _mm256_add_ps(ax, _mm256_and_ps(m, _mm256_mul_ps(f, ex)));
    ay = _mm256_add_ps(ay, _mm256_and_ps(m, _mm256_mul_ps(f, ey)));
  }
}

inline float sum8(__m256 v) {
  alignas(32) float l[8];
  _mm256_store_ps(l, v);
  return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}
#endif

}  // namespace

namespace {
// Largest squared displacements of one sweep: since the agents were bucketed, and in the sweep.
struct Moves {
  float sinceBucket2 = 0.0f, sweep2 = 0.0f;
};
}  // namespace

void CollisionResolver::resolve(Agents& agents, const StaticObstacles& obstacles, const DomainBox& domain,
                                const CollisionResolutionParams& params) {
  bucketings_ = 0;
  sweeps_ = 0;
  const std::size_t n = agents.size();
  if (n == 0 || params.iterations <= 0) return;
  const float s = params.separation;
  const float rmax = static_cast<float>(parallelMax(n, [&](std::size_t i) { return agents.radius[i]; }));
  if (!(rmax > 0.0f)) return;
  // Interaction range: no pair farther apart than this is pushed. The cells get a skin on top, so
  // agents may move a little before the buckets have to be redone.
  const float range = s * 2.0f * rmax;
  const float tolerance2 = (params.tolerance * 2.0f * rmax) * (params.tolerance * 2.0f * rmax);
  constexpr float kSkin = 0.5f;
  bucket(agents, range * (1.0f + kSkin));
  int bucketedAt = 0;           // the first sweep on the current buckets
  float movedSinceBucket2 = 0;  // largest squared displacement since then

  for (int it = 0; it < params.iterations; ++it) {
    const int nx = grid_.cellsX(), ny = grid_.cellsY();
    const std::uint32_t* agent = agent_.data();
    const float* xs = x_.data();
    const float* ys = y_.data();
    float* nextX = nextX_.data();
    float* nextY = nextY_.data();
    const Vec2f* bucketed = bucketed_.data();
    const float* rad = radius_.data();
    const float* yield = yield_.data();
    const std::uint8_t* scripted = scripted_.data();
    const std::uint8_t* moved = moved_.data();
    std::uint8_t* movedNext = movedNext_.data();
    const bool everything = it == bucketedAt;  // no earlier sweep on these buckets to compare with

    // The agents of one cell: next from current positions. Their neighbours are the three
    // contiguous slot ranges of the stencil. worst: the largest squared displacement since
    // bucketing of those that move.
    auto sweepCell = [&](std::uint32_t first, std::uint32_t last, const NeighbourGrid::Stencil& st, Moves& worst) {
      // Nothing in the stencil moved in the last sweep: its agents' inputs are those of that
      // sweep, in which they did not move, so they do not move now (skipping is exact).
      if (!everything) {
        bool dirty = false;
        for (int cy = st.y0; cy <= st.y1; ++cy)
          for (int cx = st.x0; cx <= st.x1; ++cx) dirty |= moved[static_cast<std::size_t>(cy) * nx + cx] != 0;
        if (!dirty) {
          std::copy(xs + first, xs + last, nextX + first);
          std::copy(ys + first, ys + last, nextY + first);
          movedNext[st.cell] = 0;
          return;
        }
      }
      std::uint8_t cellMoved = 0;
      for (std::uint32_t k = first; k < last; ++k) {
        const Vec2f xi(xs[k], ys[k]);
        nextX[k] = xi.x();
        nextY[k] = xi.y();
        if (scripted[k]) continue;
        const float ri = rad[k];
        float dx = 0.0f, dy = 0.0f;
        int coincident = 0;
#if defined(__AVX2__)
        __m256 ax = _mm256_setzero_ps(), ay = _mm256_setzero_ps();
        for (int q = 0; q < st.count; ++q)
          pushAvx(xs, ys, rad, yield, st.lo[q], st.hi[q], k, xi.x(), xi.y(), ri, s, ax, ay, coincident);
        dx = sum8(ax);
        dy = sum8(ay);
#else
        for (int q = 0; q < st.count; ++q)
          pushScalar(xs, ys, rad, yield, st.lo[q], st.hi[q], k, xi.x(), xi.y(), ri, s, dx, dy, coincident);
#endif
        if (coincident > 0) {
          // Coincident pairs: a direction hashed from the pair, opposite for the two (rare).
          for (int q = 0; q < st.count; ++q)
            for (std::uint32_t j = st.lo[q]; j < st.hi[q]; ++j) {
              const float ex = xi.x() - xs[j], ey = xi.y() - ys[j];
              const float target = s * (ri + rad[j]);
              const float d2 = ex * ex + ey * ey, t2 = target * target;
              if (j == k || d2 >= t2 || d2 > 1e-14f * t2) continue;
              const Vec2f dir = coincidentDirection(agent[k], agent[j]);
              const float push = yield[j] * (target - std::sqrt(d2));
              dx += push * dir.x();
              dy += push * dir.y();
            }
        }
        Vec2f x(xi.x() + dx, xi.y() + dy);
        if (!obstacles.empty()) x = obstacles.pushOut(x, ri);
        for (int a = 0; a < 2; ++a) {
          const float lo = domain.lo[a] + ri, hi = domain.hi[a] - ri;
          x[a] = lo <= hi ? std::clamp(x[a], lo, hi) : 0.5f * (domain.lo[a] + domain.hi[a]);
        }
        if (x == xi) continue;
        nextX[k] = x.x();
        nextY[k] = x.y();
        cellMoved = 1;
        worst.sinceBucket2 = std::max(worst.sinceBucket2, (x - bucketed[k]).squaredNorm());
        worst.sweep2 = std::max(worst.sweep2, (x - xi).squaredNorm());
      }
      movedNext[st.cell] = cellMoved;
    };

    // Rows of cells per task: about 2048 agents. The max does not depend on how tasks combine.
    const std::size_t grain = std::max<std::size_t>(1, static_cast<std::size_t>(ny) * 2048 / n);
    const Moves moves = tbb::parallel_reduce(
        tbb::blocked_range<int>(0, ny, grain), Moves{},
        [&](const tbb::blocked_range<int>& rows, Moves worst) {
          grid_.forEachCellInRows(rows.begin(), rows.end(),
                                  [&](std::uint32_t first, std::uint32_t last, const NeighbourGrid::Stencil& st) {
                                    sweepCell(first, last, st, worst);
                                  });
          return worst;
        },
        [](const Moves& a, const Moves& b) {
          return Moves{std::max(a.sinceBucket2, b.sinceBucket2), std::max(a.sweep2, b.sweep2)};
        });
    const float moved2 = moves.sinceBucket2;
    x_.swap(nextX_);
    y_.swap(nextY_);
    moved_.swap(movedNext_);
    ++sweeps_;
    // Converged: the last sweep moved nobody by more than the tolerance (the max is exact whatever
    // the thread count, so the number of sweeps is deterministic too).
    if (it + 1 == params.iterations || moves.sweep2 <= tolerance2) break;
    // A pair within range now was within range + 2 * max displacement when bucketed: still in
    // each other's stencil while that fits in a cell (with a margin for round-off). Otherwise the
    // agents are bucketed again where they are now. (An agent that did not move in a sweep has
    // the displacement of the last sweep it moved in.)
    movedSinceBucket2 = std::max(movedSinceBucket2, moved2);
    if (range + 2.0f * std::sqrt(movedSinceBucket2) * 1.001f + 1e-6f * range >= grid_.cellSize()) {
      rebucket(range * (1.0f + kSkin));
      bucketedAt = it + 1;
      movedSinceBucket2 = 0.0f;
    }
  }
  scatter(agents);
}

void CollisionResolver::scatter(Agents& agents) const {
  parallelFor(
      0, agent_.size(), [&](std::size_t k) { agents.position[agent_[k]] = Vec2f(x_[k], y_[k]); }, 4096);
}

}  // namespace msim::crowd
