#include "msim/crowd/collision_resolution.hpp"

#include <algorithm>
#include <cmath>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"
#include "msim/crowd/collision_kernels.hpp"

namespace msim::crowd {

using namespace collision_kernels;

namespace {
// Skins on top of the interaction range (fractions of it): cells 1.5 ranges wide, so agents may
// move a quarter range from where they were bucketed before a pair within range could lie beyond
// the neighbouring cells. In the 100k circle the farthest agent gets to about 0.9 of that in a
// call, so one bucketing per call most of the time.
constexpr float kCellSkin = 0.5f;
// Gauss-Seidel sweeps after the first are whole while more than one agent in kLocalShare is
// active, else only around the active agents, which costs about 10-15 times as much per agent
// (0.3-0.45 us against 30-45 ns over two cores, circle 100k: scattered reads of the cells around
// each active agent).
constexpr std::size_t kLocalShare = 16;
}  // namespace

void CollisionResolver::bucket(const Agents& agents, float cellSize) {
  grid_.build(agents.position, cellSize);
  ++bucketings_;
  const std::size_t n = agents.size();
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  const std::span<const Vec2f> sorted = grid_.sortedPoints();
  // Padding: far away (the squared distance overflows to inf), so never within range.
  for (auto* v : {&x_, &y_, &nextX_, &nextY_, &prevX_, &prevY_, &bucketX_, &bucketY_}) v->resize(n + kPad, 1e30f);
  for (auto* v : {&radius_, &yield_, &tmpRadius_, &tmpYield_}) v->resize(n + kPad, 0.0f);
  far_.resize(n + kPad, 0.0f);
  for (auto* v : {&checkX_, &checkY_}) v->resize(n);
  active_.resize(n);
  touchedMark_.assign(n, 0);
  scripted_.resize(n);
  agent_.resize(n);
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t i = order[k];
        agent_[k] = i;
        x_[k] = bucketX_[k] = sorted[k].x();
        y_[k] = bucketY_[k] = sorted[k].y();
        radius_[k] = agents.radius[i];
        scripted_[k] = agents.model[i] == AgentModel::Scripted ? 1 : 0;
        yield_[k] = scripted_[k] ? 1.0f : 0.5f;
      },
      4096);
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
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t old = from[k];
        x_[k] = bucketX_[k] = sorted[k].x();
        y_[k] = bucketY_[k] = sorted[k].y();
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

void CollisionResolver::resolve(Agents& agents, const StaticObstacles& obstacles, const DomainBox& domain,
                                const CollisionResolutionParams& params) {
  bucketings_ = 0;
  sweeps_ = 0;
  localSweeps_ = 0;
  redone_ = 0;
  const std::size_t n = agents.size();
  if (n == 0 || params.iterations <= 0) return;
  const float rmax = static_cast<float>(parallelMax(n, [&](std::size_t i) { return agents.radius[i]; }));
  if (!(rmax > 0.0f)) return;
  // Interaction range: no pair farther apart than this is pushed. The cells are made with a skin
  // on top, so agents may move a little before they have to be bucketed again.
  const float range = params.separation * 2.0f * rmax;
  const float tolerance = params.tolerance * 2.0f * rmax;
  const bool gaussSeidel = params.sweeps == CollisionResolutionParams::Sweeps::GaussSeidel;
  bucket(agents, range * (1.0f + kCellSkin));
  if (gaussSeidel)
    resolveGaussSeidel(obstacles, domain, params, range, tolerance * tolerance);
  else
    resolveJacobi(obstacles, domain, params, range, tolerance * tolerance);
  scatter(agents);
}

void CollisionResolver::resolveGaussSeidel(const StaticObstacles& obstacles, const DomainBox& domain,
                                           const CollisionResolutionParams& params, float range, float tolerance2) {
  const float cellSize = range * (1.0f + kCellSkin), s = params.separation;
  const std::size_t n = agent_.size();
  // A pair within range at some moment of a sweep was within range + 2 F when bucketed, F bounding
  // every agent's distance from its bucketed position during the sweep: its agents are in
  // neighbouring cells while that is below the cell size (with a margin for round-off).
  auto tooFar = [&](float f) { return range + 2.0f * f * 1.001f + 1e-6f * range >= cellSize; };
  auto restoreSweepStart = [&] {
    std::copy(prevX_.begin(), prevX_.begin() + static_cast<std::ptrdiff_t>(n), x_.begin());
    std::copy(prevY_.begin(), prevY_.begin() + static_cast<std::ptrdiff_t>(n), y_.begin());
  };
  auto wholeSweep = [&] {
    const SweepMoves moves = gaussSeidelSweep(obstacles, domain, s, tolerance2);
    prevX_.swap(nextX_);  // the end positions start the next sweep
    prevY_.swap(nextY_);
    return moves;
  };
  // A whole sweep on new buckets (the first sweep on them is kept whatever it moved: there a
  // single sweep moved that far, from deep overlaps).
  auto sweepOnNewBuckets = [&] {
    startSweeps();
    return wholeSweep();
  };
  SweepMoves moves = sweepOnNewBuckets();
  ++sweeps_;
  float start = 0.0f;  // largest distance from the bucketed positions at the start of the sweep
  bool fresh = true;   // the last sweep was the first on its buckets
  bool activeListed = false;  // activeSlots_ holds the active slots (a local sweep listed them)
  // Converged: no agent moved more than the tolerance since its pairs were last projected (the
  // count does not depend on the thread count, so the number of sweeps is deterministic too).
  while (sweeps_ < params.iterations && moves.active > 0) {
    const float end = std::sqrt(moves.end2);
    if (moves.active * kLocalShare <= n && tolerance2 > 0.0f) {
      if (!activeListed) gatherActive();
      moves = localSweep(obstacles, domain, s, range, tolerance2, moves.end2);
      activeListed = true;
      ++localSweeps_;
      ++sweeps_;
      fresh = false;
      start = std::sqrt(moves.end2);
      continue;
    }
    activeListed = false;
    // Gauss-Seidel corrections shrink from sweep to sweep: expect the next one to carry agents
    // beyond where the last one left them by at most half as far as that one carried them beyond
    // where it started, and bucket again before it if that would not fit. (Guessing short costs a
    // redone sweep, guessing long a bucketing.)
    const float excursion = std::max(std::sqrt(moves.far2) - start, 0.0f);
    start = end;
    if (tooFar(end + 0.5f * excursion)) {
      rebucket(cellSize);
      moves = sweepOnNewBuckets();
      fresh = true;
      start = 0.0f;
      ++sweeps_;
      continue;
    }
    moves = gaussSeidelSweep(obstacles, domain, s, tolerance2);
    if (!fresh && tooFar(std::sqrt(moves.far2))) {  // a pair may have been missed: redo on new buckets
      ++redone_;
      restoreSweepStart();
      rebucket(cellSize);
      moves = sweepOnNewBuckets();
      fresh = true;
      start = 0.0f;
    } else {
      prevX_.swap(nextX_);
      prevY_.swap(nextY_);
      fresh = false;
    }
    ++sweeps_;
  }
}

void CollisionResolver::startSweeps() {
  const std::size_t n = agent_.size();
  std::fill(far_.begin(), far_.begin() + static_cast<std::ptrdiff_t>(n), 0.0f);
  std::copy(x_.begin(), x_.begin() + static_cast<std::ptrdiff_t>(n), prevX_.begin());
  std::copy(y_.begin(), y_.begin() + static_cast<std::ptrdiff_t>(n), prevY_.begin());
}

CollisionResolver::SweepMoves CollisionResolver::gaussSeidelSweep(const StaticObstacles& obstacles,
                                                                  const DomainBox& domain, float s, float tolerance2) {
  const int nx = grid_.cellsX(), ny = grid_.cellsY();
  const std::uint32_t* start = grid_.cellStarts().data();
  const std::size_t n = agent_.size();
  const SweepSlots slots{x_.data(),      y_.data(),     far_.data(),   bucketX_.data(),
                         bucketY_.data(), radius_.data(), yield_.data(), agent_.data()};
  // Each pair once, owned by its first agent in cell order: an agent's partners are the later
  // slots of its cell and those of the cell to its right (one contiguous range), and the slots of
  // the three cells above (another).
  auto sweepRow = [&](int cy) {
    for (int cx = 0; cx < nx; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy) * nx + cx;
      const std::uint32_t first = start[c], last = start[c + 1];
      if (first == last) continue;
      std::uint32_t lo[2], hi[2];
      hi[0] = start[c + (cx + 1 < nx ? 2 : 1)];
      lo[1] = hi[1] = 0;
      if (cy + 1 < ny) {
        const std::size_t row = static_cast<std::size_t>(cy + 1) * nx;
        lo[1] = start[row + std::max(cx - 1, 0)];
        hi[1] = start[row + std::min(cx + 1, nx - 1) + 1];
      }
      for (std::uint32_t i = first; i < last; ++i) {
        lo[0] = i + 1;
        projectRanges(slots, i, lo, hi, 2, s);
      }
    }
  };
  // A row's pairs reach into that row and the one above only, so the even rows can be done in
  // parallel, then the odd ones; each row in its fixed order. Rows per task: about 1024 agents.
  // The partition does not change the result.
  const int grain = static_cast<int>(std::max<std::size_t>(1, static_cast<std::size_t>(ny) * 1024 / n));
  for (int phase = 0; phase < 2; ++phase) {
    const int rows = (ny - phase + 1) / 2;
    tbb::parallel_for(tbb::blocked_range<int>(0, rows, grain), [&](const tbb::blocked_range<int>& r) {
      for (int k = r.begin(); k != r.end(); ++k) sweepRow(2 * k + phase);
    });
  }

  // Obstacles and domain, and the displacements (end positions into nextX_, nextY_).
  float* xs = x_.data();
  float* ys = y_.data();
  const float* rad = radius_.data();
  const std::uint8_t* scripted = scripted_.data();
  if (!obstacles.empty())
    parallelFor(
        0, n,
        [&](std::size_t k) {
          if (scripted[k]) return;
          const Vec2f q = obstacles.pushOut(Vec2f(xs[k], ys[k]), rad[k]);
          xs[k] = q.x();
          ys[k] = q.y();
        },
        4096);
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 4096), SweepMoves{},
      [&](const tbb::blocked_range<std::size_t>& r, SweepMoves w) {
        clampIntoDomain(r.begin(), r.end(), domain, tolerance2, w);
        return w;
      },
      [](const SweepMoves& a, const SweepMoves& b) {
        return SweepMoves{std::max(a.far2, b.far2), std::max(a.end2, b.end2), a.active + b.active};
      });
}

void CollisionResolver::clampIntoDomain(std::size_t k0, std::size_t k1, const DomainBox& domain, float tolerance2,
                                        SweepMoves& w) {
  // Branch-free, so that it vectorizes.
  float* __restrict xs = x_.data();
  float* __restrict ys = y_.data();
  float* __restrict far = far_.data();
  float* __restrict endX = nextX_.data();
  float* __restrict endY = nextY_.data();
  const float* __restrict startX = prevX_.data();
  const float* __restrict startY = prevY_.data();
  const float* __restrict rad = radius_.data();
  const std::uint8_t* __restrict scripted = scripted_.data();
  const float* __restrict bucketX = bucketX_.data();
  const float* __restrict bucketY = bucketY_.data();
  float* __restrict checkX = checkX_.data();
  float* __restrict checkY = checkY_.data();
  std::uint8_t* __restrict active = active_.data();
  const float midX = 0.5f * (domain.lo.x() + domain.hi.x()), midY = 0.5f * (domain.lo.y() + domain.hi.y());
  float far2 = w.far2, end2 = w.end2;
  std::size_t count = w.active;
  for (std::size_t k = k0; k < k1; ++k) {
    const float r = rad[k];
    const float loX = domain.lo.x() + r, hiX = domain.hi.x() - r, loY = domain.lo.y() + r, hiY = domain.hi.y() - r;
    const float cx = loX <= hiX ? std::min(std::max(xs[k], loX), hiX) : midX;
    const float cy = loY <= hiY ? std::min(std::max(ys[k], loY), hiY) : midY;
    const float x = scripted[k] ? xs[k] : cx, y = scripted[k] ? ys[k] : cy;
    const float bx = x - bucketX[k], by = y - bucketY[k];
    const float sx = x - startX[k], sy = y - startY[k];
    const float e2 = bx * bx + by * by;
    far2 = std::max(far2, far[k]);
    end2 = std::max(end2, e2);
    // A whole sweep projected every pair, each agent's last during the sweep: from where it
    // started, it counts as active if it moved more than the tolerance since.
    const std::uint8_t moved = sx * sx + sy * sy > tolerance2 ? 1 : 0;
    active[k] = moved;
    count += moved;
    checkX[k] = startX[k];
    checkY[k] = startY[k];
    far[k] = e2;  // where the next sweep starts
    xs[k] = endX[k] = x;
    ys[k] = endY[k] = y;
  }
  w = SweepMoves{far2, end2, count};
}

void CollisionResolver::gatherActive() {
  activeSlots_.clear();
  for (std::size_t k = 0; k < active_.size(); ++k)
    if (active_[k]) activeSlots_.push_back(static_cast<std::uint32_t>(k));
}

CollisionResolver::SweepMoves CollisionResolver::localSweep(const StaticObstacles& obstacles, const DomainBox& domain,
                                                            float s, float range, float tolerance2, float lastEnd2) {
  const SweepSlots slots{x_.data(),      y_.data(),     far_.data(),   bucketX_.data(),
                         bucketY_.data(), radius_.data(), yield_.data(), agent_.data()};
  const float cellSize = grid_.cellSize();
  // The active agents by row of cells (activeSlots_ is in slot order, so in row order).
  const int nx = grid_.cellsX();
  const std::uint32_t* start = grid_.cellStarts().data();
  std::size_t groups = 0;
  int row = 0;
  for (std::size_t q = 0; q < activeSlots_.size();) {
    while (start[static_cast<std::size_t>(row + 1) * nx] <= activeSlots_[q]) ++row;
    const std::uint32_t rowEnd = start[static_cast<std::size_t>(row + 1) * nx];
    std::size_t end = q;
    while (end < activeSlots_.size() && activeSlots_[end] < rowEnd) ++end;
    if (groups == rowGroups_.size()) rowGroups_.emplace_back();
    RowGroup& g = rowGroups_[groups++];
    g.row = row;
    g.begin = q;
    g.end = end;
    g.touched.clear();
    g.deferred.clear();
    g.active.clear();
    q = end;
  }
  // Active agent i of group g: its pairs with every agent within range now, which lies in the
  // cells within range + F of i, F bounding every agent's distance from where it was bucketed
  // (the cells hold the bucketed positions); F grows as the sweep moves agents. While
  // range + 2 F < cell size those cells are in the rows next to i's, so groups three rows apart
  // read and move disjoint agents: rows with row % 3 == c run in parallel for c = 0, 1, 2, each
  // group in slot order. An agent for which F has grown too far is deferred to a serial pass.
  // The result does not depend on the thread count.
  auto project = [&](RowGroup& g, std::uint32_t i, float& farthest2, bool parallel) {
    const float f = std::sqrt(farthest2) * 1.001f + 1e-6f * range;
    if (parallel && range + 2.0f * f >= cellSize) return false;
    // The slots near i, row by row, without i itself.
    g.lo.clear();
    g.hi.clear();
    grid_.forEachSlotRowNear(Vec2f(x_[i], y_[i]), range + f, [&](std::uint32_t first, std::uint32_t last) {
      if (first <= i && i < last) {
        g.lo.push_back(first);
        g.hi.push_back(i);
        first = i + 1;
      }
      g.lo.push_back(first);
      g.hi.push_back(last);
    });
    // The agents the projection moves: i and every partner it pushes.
    auto touch = [&](std::uint32_t k) {
      farthest2 = std::max(farthest2, far_[k]);
      if (touchedMark_[k]) return;
      touchedMark_[k] = 1;
      g.touched.push_back(k);
    };
    checkX_[i] = x_[i];  // all of i's pairs are projected now
    checkY_[i] = y_[i];
    projectRanges(slots, i, g.lo.data(), g.hi.data(), static_cast<int>(g.lo.size()), s, touch);
    touch(i);
    return true;
  };
  float farthest2 = lastEnd2;
  for (int colour = 0; colour < 3; ++colour) {
    tbb::parallel_for(std::size_t(0), groups, [&](std::size_t k) {
      RowGroup& g = rowGroups_[k];
      if (g.row % 3 != colour) return;
      g.farthest2 = farthest2;
      for (std::size_t q = g.begin; q < g.end; ++q)
        if (!project(g, activeSlots_[q], g.farthest2, true)) g.deferred.push_back(activeSlots_[q]);
    });
    for (std::size_t k = 0; k < groups; ++k)
      if (rowGroups_[k].row % 3 == colour) farthest2 = std::max(farthest2, rowGroups_[k].farthest2);
  }
  for (std::size_t k = 0; k < groups; ++k)
    for (const std::uint32_t i : rowGroups_[k].deferred) project(rowGroups_[k], i, farthest2, false);

  // The end of the sweep for the agents it moved (the others stay where the last sweep left
  // them): obstacles, domain, distances, and the next sweep's active agents in slot order.
  const SweepMoves moves = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, groups, 1), SweepMoves{lastEnd2, lastEnd2, 0},
      [&](const tbb::blocked_range<std::size_t>& r, SweepMoves m) {
        for (std::size_t k = r.begin(); k != r.end(); ++k)
          for (const std::uint32_t slot : rowGroups_[k].touched) {
            Vec2f x(x_[slot], y_[slot]);
            if (!scripted_[slot]) {
              if (!obstacles.empty()) x = obstacles.pushOut(x, radius_[slot]);
              for (int a = 0; a < 2; ++a) {
                const float lo = domain.lo[a] + radius_[slot], hi = domain.hi[a] - radius_[slot];
                x[a] = lo <= hi ? std::clamp(x[a], lo, hi) : 0.5f * (domain.lo[a] + domain.hi[a]);
              }
            }
            x_[slot] = prevX_[slot] = x.x();  // prevX_ == x_ between sweeps
            y_[slot] = prevY_[slot] = x.y();
            touchedMark_[slot] = 0;
            const float e2 = (x - Vec2f(bucketX_[slot], bucketY_[slot])).squaredNorm();
            m.far2 = std::max({m.far2, far_[slot], e2});
            m.end2 = std::max(m.end2, e2);
            far_[slot] = e2;
            const float cx = x.x() - checkX_[slot], cy = x.y() - checkY_[slot];
            active_[slot] = cx * cx + cy * cy > tolerance2 ? 1 : 0;
            m.active += active_[slot];
            if (active_[slot]) rowGroups_[k].active.push_back(slot);
          }
        return m;
      },
      [](const SweepMoves& a, const SweepMoves& b) {
        return SweepMoves{std::max(a.far2, b.far2), std::max(a.end2, b.end2), a.active + b.active};
      });
  activeSlots_.clear();
  for (std::size_t k = 0; k < groups; ++k)
    activeSlots_.insert(activeSlots_.end(), rowGroups_[k].active.begin(), rowGroups_[k].active.end());
  std::sort(activeSlots_.begin(), activeSlots_.end());
  return moves;
}

namespace {
// Largest squared displacements of one Jacobi sweep: since the agents were bucketed, and in the sweep.
struct Moves {
  float sinceBucket2 = 0.0f, sweep2 = 0.0f;
};
}  // namespace

void CollisionResolver::resizeCellFlags() {
  const std::size_t cells = static_cast<std::size_t>(grid_.cellsX()) * grid_.cellsY();
  moved_.resize(cells);
  movedNext_.resize(cells);
}

void CollisionResolver::resolveJacobi(const StaticObstacles& obstacles, const DomainBox& domain,
                                      const CollisionResolutionParams& params, float range, float tolerance2) {
  const std::size_t n = agent_.size();
  const float s = params.separation;
  const float cellSize = range * (1.0f + kCellSkin);
  resizeCellFlags();
  int bucketedAt = 0;           // the first sweep on the current buckets
  float movedSinceBucket2 = 0;  // largest squared displacement since then
  for (int it = 0; it < params.iterations; ++it) {
    const int nx = grid_.cellsX(), ny = grid_.cellsY();
    const std::uint32_t* agent = agent_.data();
    const float* xs = x_.data();
    const float* ys = y_.data();
    float* nextX = nextX_.data();
    float* nextY = nextY_.data();
    const float* bucketX = bucketX_.data();
    const float* bucketY = bucketY_.data();
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
        worst.sinceBucket2 = std::max(worst.sinceBucket2, (x - Vec2f(bucketX[k], bucketY[k])).squaredNorm());
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
      rebucket(cellSize);
      resizeCellFlags();
      bucketedAt = it + 1;
      movedSinceBucket2 = 0.0f;
    }
  }
}

void CollisionResolver::scatter(Agents& agents) const {
  parallelFor(
      0, agent_.size(), [&](std::size_t k) { agents.position[agent_[k]] = Vec2f(x_[k], y_[k]); }, 4096);
}

}  // namespace msim::crowd
