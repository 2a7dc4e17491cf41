#include "msim/crowd/collision_resolution.hpp"

#include <algorithm>
#include <atomic>
#include <cmath>
#include <limits>


#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"
#include "msim/crowd/collision_kernels.hpp"

namespace msim::crowd {

using namespace collision_kernels;


void CollisionResolver::bucket(const Agents& agents, float cellSize) {
  grid_.build(agents.position, cellSize);
  ++bucketings_;
  const std::size_t n = agents.size();
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  const std::span<const Vec2f> sorted = grid_.sortedPoints();
  // Padding: far away (the squared distance overflows to inf), so never within range.
  for (auto* v : {&x_, &y_, &nextX_, &nextY_, &prevX_, &prevY_}) v->resize(n + kPad, 1e30f);
  path_.assign(n + kPad, 0.0f);
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
  noop_.resize(cells);
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
// Largest squared displacements of one sweep: since the agents were bucketed, and in the sweep.
struct Moves {
  float sinceBucket2 = 0.0f, sweep2 = 0.0f;
};
}  // namespace

void CollisionResolver::resolve(Agents& agents, const StaticObstacles& obstacles, const DomainBox& domain,
                                const CollisionResolutionParams& params) {
  bucketings_ = 0;
  sweeps_ = 0;
  redone_ = 0;
  const std::size_t n = agents.size();
  if (n == 0 || params.iterations <= 0) return;
  const float s = params.separation;
  const float rmax = static_cast<float>(parallelMax(n, [&](std::size_t i) { return agents.radius[i]; }));
  if (!(rmax > 0.0f)) return;
  // Interaction range: no pair farther apart than this is pushed. The cells get a skin on top, so
  // agents may move a little before the buckets have to be redone.
  const float range = s * 2.0f * rmax;
  const float tolerance2 = (params.tolerance * 2.0f * rmax) * (params.tolerance * 2.0f * rmax);
  // Gauss-Seidel: the bound on the distance moved counts every correction (agents pushed back and
  // forth in a jam), so a wider skin; 0.75-1.5 measured the same, 0.5 re-buckets 5 times per
  // call instead of 3.
  const float kSkin = params.sweeps == CollisionResolutionParams::Sweeps::Jacobi ? 0.5f : 1.0f;
  bucket(agents, range * (1.0f + kSkin));
  int bucketedAt = 0;           // the first sweep on the current buckets
  float movedSinceBucket2 = 0;  // largest squared displacement since then

  if (params.sweeps == CollisionResolutionParams::Sweeps::GaussSeidel) {
    auto keepStart = [&] {
      startEnd2_ = 0.0f;  // called right after bucketing: the positions are the bucketed ones
      std::copy(x_.begin(), x_.begin() + static_cast<std::ptrdiff_t>(n), prevX_.begin());
      std::copy(y_.begin(), y_.begin() + static_cast<std::ptrdiff_t>(n), prevY_.begin());
    };
    keepStart();
    bool fresh = true;  // the first sweep on the current buckets
    for (int it = 0; it < params.iterations; ++it) {
      SweepMoves moves = gaussSeidelSweep(obstacles, domain, s, fresh);
      // A pair within range at some moment of the sweep was within range + 2 D when bucketed, D
      // bounding every agent's distance from its bucketed position during the sweep (distance
      // at the start plus the lengths of its corrections). If that no longer fits in a cell, a
      // pair may have been missed: the sweep is undone and redone on new buckets. (Not on fresh
      // buckets: there a single sweep moved that far, from deep overlaps, and is kept.)
      auto tooFar = [&](float d) { return range + 2.0f * d * 1.001f + 1e-6f * range >= grid_.cellSize(); };
      if (!fresh && tooFar(std::sqrt(moves.sinceBucket2))) {
        ++redone_;
        std::copy(prevX_.begin(), prevX_.begin() + static_cast<std::ptrdiff_t>(n), x_.begin());
        std::copy(prevY_.begin(), prevY_.begin() + static_cast<std::ptrdiff_t>(n), y_.begin());
        rebucket(range * (1.0f + kSkin));
        keepStart();
        moves = gaussSeidelSweep(obstacles, domain, s, true);
      }
      fresh = false;
      startEnd2_ = moves.end2;
      prevX_.swap(nextX_);  // the end positions start the next sweep
      prevY_.swap(nextY_);
      moved_.swap(movedNext_);
      ++sweeps_;
      if (it + 1 == params.iterations || moves.sweep2 <= tolerance2) break;
      // Expect the next sweep to move agents about as far as this one: re-bucket before it if the
      // bound would not fit.
      if (tooFar(std::sqrt(moves.end2) + moves.path)) {
        rebucket(range * (1.0f + kSkin));
        keepStart();
        fresh = true;
      }
    }
    scatter(agents);
    return;
  }

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


CollisionResolver::SweepMoves CollisionResolver::gaussSeidelSweep(const StaticObstacles& obstacles,
                                                                  const DomainBox& domain, float s,
                                                                  bool everything) {
  const int nx = grid_.cellsX(), ny = grid_.cellsY();
  const std::uint32_t* start = grid_.cellStarts().data();
  const std::size_t n = agent_.size();
  float* xs = x_.data();
  float* ys = y_.data();
  float* path = path_.data();
  const float* rad = radius_.data();
  const float* yield = yield_.data();
  const std::uint8_t* scripted = scripted_.data();
  const std::uint32_t* agent = agent_.data();
  const std::uint8_t* moved = moved_.data();
  std::uint8_t* movedNext = movedNext_.data();
  std::uint8_t* noop = noop_.data();
  std::fill(movedNext_.begin(), movedNext_.end(), std::uint8_t(0));

  // Cell (cx, cy) projects the pairs of its agents with the later agents of its own cell, with
  // those of the cell to its right (the next slots) and with those of the three cells above: every
  // pair once. It reads and writes only that footprint, which lies in rows cy and cy + 1, so the
  // even rows can be done in parallel, then the odd ones.
  auto doCell = [&](int cx, int cy) {
    const std::size_t c = static_cast<std::size_t>(cy) * nx + cx;
    const std::uint32_t first = start[c], last = start[c + 1];
    if (first == last) return;
    const int fx0 = std::max(cx - 1, 0), fx1 = std::min(cx + 1, nx - 1);
    const std::uint32_t endSame = start[c + (cx + 1 < nx ? 2 : 1)];
    std::uint32_t lo2 = 0, hi2 = 0;
    const bool above = cy + 1 < ny;
    const std::size_t row = static_cast<std::size_t>(cy + 1) * nx;
    if (above) {
      lo2 = start[row + fx0];
      hi2 = start[row + fx1 + 1];
    }
    // Skipped when its last pass moved nobody and nothing in the footprint moved since (in the
    // last sweep or this one): the same inputs give the same (no) result.
    if (!everything && noop[c]) {
      bool dirty = false;
      for (int x = cx; x <= fx1; ++x) dirty |= (moved[c - cx + x] | movedNext[c - cx + x]) != 0;
      if (above)
        for (int x = fx0; x <= fx1; ++x) dirty |= (moved[row + x] | movedNext[row + x]) != 0;
      if (!dirty) return;
    }
    bool changed = false;
#if defined(__AVX2__)
    // Usual case: the cell and its right neighbour fit in two blocks of 8 slots, the three cells
    // above in three. All pairs are done in registers (or spilled to the stack, which forwards),
    // stored back once: no store-to-load dependency through the slot arrays.
    if (endSame - first <= 16 && hi2 - lo2 <= 24) {
      // Blocks 0-1: the cell and its right neighbour; 2-4: the three cells above.
      Block blk[5];
      const std::uint32_t n1 = endSame - first, n2 = hi2 - lo2;
      const int nb1 = static_cast<int>((n1 + 7) / 8), nb2 = static_cast<int>((n2 + 7) / 8);
      for (int q = 0; q < nb1; ++q)
        blk[q].load(xs, ys, rad, yield, path, first + 8 * q, std::min<std::uint32_t>(8, n1 - 8 * q));
      for (int q = 0; q < nb2; ++q)
        blk[2 + q].load(xs, ys, rad, yield, path, lo2 + 8 * q, std::min<std::uint32_t>(8, n2 - 8 * q));
      const __m256 sv = _mm256_set1_ps(s);
      const __m256i lanes = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
      for (std::uint32_t l = 0; l < last - first; ++l) {
        const int bi = static_cast<int>(l / 8), li = static_cast<int>(l % 8);
        Block& own = blk[bi];
        const __m256 xv = lane(own.x, li), yv = lane(own.y, li), rv = lane(own.r, li), yI = lane(own.w, li);
        const __m256 movI = _mm256_cmp_ps(yI, _mm256_set1_ps(0.75f), _CMP_LT_OQ);
        __m256 ax = _mm256_setzero_ps(), ay = _mm256_setzero_ps(), pv = _mm256_setzero_ps();
        const std::uint32_t i = first + l;
        // The later slots of the cell and those of its right neighbour.
        for (int q = bi; q < nb1; ++q) {
          const __m256i later = _mm256_cmpgt_epi32(lanes, _mm256_set1_epi32(li - 8 * (q - bi)));
          changed |= projectBlock(blk[q], _mm256_castsi256_ps(_mm256_and_si256(blk[q].valid, later)), xv, yv, rv, yI,
                                  movI, sv, i, agent, ax, ay, pv);
        }
        for (int q = 2; q < 2 + nb2; ++q)
          changed |= projectBlock(blk[q], _mm256_castsi256_ps(blk[q].valid), xv, yv, rv, yI, movI, sv, i, agent, ax,
                                  ay, pv);
        const __m256 self = _mm256_castsi256_ps(_mm256_cmpeq_epi32(lanes, _mm256_set1_epi32(li)));
        own.x = _mm256_add_ps(own.x, _mm256_and_ps(self, hsumAll(ax)));
        own.y = _mm256_add_ps(own.y, _mm256_and_ps(self, hsumAll(ay)));
        own.path = _mm256_add_ps(own.path, _mm256_and_ps(self, hsumAll(pv)));
      }
      for (int q = 0; q < nb1; ++q) blk[q].store(xs, ys, path);
      for (int q = 2; q < 2 + nb2; ++q) blk[q].store(xs, ys, path);
      noop[c] = changed ? 0 : 1;
      if (changed) {
        for (int x = cx; x <= fx1; ++x) movedNext[c - cx + x] = 1;
        if (above)
          for (int x = fx0; x <= fx1; ++x) movedNext[row + x] = 1;
      }
      return;
    }
#endif
    for (std::uint32_t i = first; i < last; ++i) {
      const float xi = xs[i], yi = ys[i], ri = rad[i], yieldI = yield[i];
      const bool movableI = scripted[i] == 0;
      float dx = 0.0f, dy = 0.0f, pathI = 0.0f;
#if defined(__AVX2__)
      __m256 ax = _mm256_setzero_ps(), ay = _mm256_setzero_ps(), pv = _mm256_setzero_ps();
      int close = 0;
      changed |= projectAvx(xs, ys, rad, yield, path, i + 1, endSame, xi, yi, ri, yieldI, movableI, s, ax, ay, pv, close);
      changed |= projectAvx(xs, ys, rad, yield, path, lo2, hi2, xi, yi, ri, yieldI, movableI, s, ax, ay, pv, close);
      dx = sum8(ax);
      dy = sum8(ay);
      pathI = sum8(pv);
      if (close > 0) {
        changed |= projectScalar(xs, ys, rad, yield, path, agent, i + 1, endSame, i, xi, yi, ri, yieldI, movableI, s,
                                 true, dx, dy, pathI);
        changed |= projectScalar(xs, ys, rad, yield, path, agent, lo2, hi2, i, xi, yi, ri, yieldI, movableI, s, true,
                                 dx, dy, pathI);
      }
#else
      for (const bool coincident : {false, true}) {
        changed |= projectScalar(xs, ys, rad, yield, path, agent, i + 1, endSame, i, xi, yi, ri, yieldI, movableI, s,
                                 coincident, dx, dy, pathI);
        changed |= projectScalar(xs, ys, rad, yield, path, agent, lo2, hi2, i, xi, yi, ri, yieldI, movableI, s,
                                 coincident, dx, dy, pathI);
      }
#endif
      xs[i] = xi + dx;
      ys[i] = yi + dy;
      path[i] += pathI;
    }
    noop[c] = changed ? 0 : 1;
    if (changed) {
      for (int x = cx; x <= fx1; ++x) movedNext[c - cx + x] = 1;
      if (above)
        for (int x = fx0; x <= fx1; ++x) movedNext[row + x] = 1;
    }
  };
  // Rows per task: about 2048 agents. The partition does not change the result.
  const int grain = static_cast<int>(std::max<std::size_t>(1, static_cast<std::size_t>(ny) * 1024 / std::max<std::size_t>(n, 1)));
  for (int phase = 0; phase < 2; ++phase) {
    const int rows = (ny - phase + 1) / 2;
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, grain), [&](const tbb::blocked_range<int>& r) {
      for (int k = r.begin(); k != r.end(); ++k) {
        const int cy = 2 * k + phase;
        for (int cx = 0; cx < nx; ++cx) doCell(cx, cy);
      }
    });
  }

  // Obstacles and domain, and the displacements (end positions into nextX_, nextY_).
  const float* px = prevX_.data();
  const float* py = prevY_.data();
  float* ex = nextX_.data();
  float* ey = nextY_.data();
  const Vec2f* bucketed = bucketed_.data();
  const std::span<const std::uint32_t> starts = grid_.cellStarts();
  SweepMoves worst = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), SweepMoves{},
      [&](const tbb::blocked_range<std::size_t>& r, SweepMoves w) {
    const std::size_t k0 = r.begin(), k1 = r.end();
    for (std::size_t k = k0; k < k1; ++k) {
      float x = xs[k], y = ys[k];
      if (!scripted[k]) {
        const float ri = rad[k];
        Vec2f q(x, y);
        if (!obstacles.empty()) q = obstacles.pushOut(q, ri);
        for (int a = 0; a < 2; ++a) {
          const float lo = domain.lo[a] + ri, hi = domain.hi[a] - ri;
          q[a] = lo <= hi ? std::clamp(q[a], lo, hi) : 0.5f * (domain.lo[a] + domain.hi[a]);
        }
        if (q.x() != x || q.y() != y) {
          x = xs[k] = q.x();
          y = ys[k] = q.y();
          // Its cell moved (the cells are those of the slots: find it, rare).
          const std::size_t c = static_cast<std::size_t>(
              std::upper_bound(starts.begin(), starts.end(), static_cast<std::uint32_t>(k)) - starts.begin() - 1);
          std::atomic_ref<std::uint8_t>(movedNext[c]).store(1, std::memory_order_relaxed);  // may straddle tasks
        }
      }
      const float bx = x - bucketed[k].x(), by = y - bucketed[k].y();
      const float sx = x - px[k], sy = y - py[k];
      w.end2 = std::max(w.end2, bx * bx + by * by);
      w.sweep2 = std::max(w.sweep2, sx * sx + sy * sy);
      w.path = std::max(w.path, path[k]);
      ex[k] = x;
      ey[k] = y;
      path[k] = 0.0f;
    }
    return w;
  },
      [](const SweepMoves& a, const SweepMoves& b) {
        return SweepMoves{0.0f, std::max(a.end2, b.end2), std::max(a.sweep2, b.sweep2), std::max(a.path, b.path)};
      });
  // Every position during the sweep was within (distance at the start) + (path) of bucketed_.
  const float startBound = std::sqrt(startEnd2_) + worst.path;
  worst.sinceBucket2 = std::max(worst.end2, startBound * startBound);
  return worst;
}

void CollisionResolver::scatter(Agents& agents) const {
  parallelFor(
      0, agent_.size(), [&](std::size_t k) { agents.position[agent_[k]] = Vec2f(x_[k], y_[k]); }, 4096);
}

}  // namespace msim::crowd
