#include "msim/crowd/orca.hpp"

#include <algorithm>
#include <array>
#include <bit>
#include <cmath>
#include <limits>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"
#include "msim/crowd/lookahead/discrete_lookahead.hpp"

namespace msim::crowd {

namespace {

// Parallel lines (in the 1D program) and vanishing bisector normals (in the 3D one).
constexpr float kEps = 1e-5f;

// Neighbour candidates are screened against the list's threshold this many at a time.
constexpr std::uint32_t kBlock = 32;

// Best point on the boundary line of planes[k], v = p + t d, within the disc and planes[0, k).
// With `maximise`, the point furthest along `objective`; otherwise the one closest to it.
bool solveOnLine(std::span<const HalfPlane> planes, std::size_t k, float maxSpeed, const Vec2f& objective,
                 bool maximise, Vec2f& result) {
  const Vec2f p = planes[k].point;
  const Vec2f d(-planes[k].normal.y(), planes[k].normal.x());
  const float b = p.dot(d);
  const float disc = b * b - (p.squaredNorm() - maxSpeed * maxSpeed);
  if (disc < 0.0f) return false;  // the line misses the speed disc
  float tLo = -b - std::sqrt(disc), tHi = -b + std::sqrt(disc);
  for (std::size_t j = 0; j < k; ++j) {
    // (p + t d - p_j) . n_j >= 0  <=>  t (d . n_j) >= (p_j - p) . n_j
    const float denom = d.dot(planes[j].normal);
    const float num = (planes[j].point - p).dot(planes[j].normal);
    if (std::abs(denom) < kEps) {
      if (num > 0.0f) return false;  // parallel and entirely outside plane j
      continue;
    }
    if (denom > 0.0f)
      tLo = std::max(tLo, num / denom);
    else
      tHi = std::min(tHi, num / denom);
    if (tLo > tHi) return false;
  }
  const float t = maximise ? (objective.dot(d) > 0.0f ? tHi : tLo) : std::clamp(d.dot(objective - p), tLo, tHi);
  result = p + t * d;
  return true;
}

// The 2D incremental program (sec. 5.2): returns the number of planes satisfied before the first
// failure (planes.size() on success); result is optimal for those.
std::size_t solvePlanar(std::span<const HalfPlane> planes, float maxSpeed, const Vec2f& objective, bool maximise,
                        Vec2f& result) {
  if (maximise)
    result = objective * maxSpeed;  // objective is a unit direction
  else
    result = objective.squaredNorm() > maxSpeed * maxSpeed ? Vec2f(objective.normalized() * maxSpeed) : objective;
  for (std::size_t k = 0; k < planes.size(); ++k) {
    if ((result - planes[k].point).dot(planes[k].normal) >= 0.0f) continue;
    const Vec2f previous = result;
    if (!solveOnLine(planes, k, maxSpeed, objective, maximise, result)) {
      result = previous;
      return k;
    }
  }
  return planes.size();
}

float penetration(const HalfPlane& h, const Vec2f& v) { return (h.point - v).dot(h.normal); }

// Infeasible case (sec. 5.2): minimise the largest penetration into the soft planes (index >=
// hard) by a 3D program, reduced plane by plane: when plane i is penetrated more than the current
// optimum, the new optimum maximises v . n_i over the region where no earlier soft plane is
// penetrated more than plane i (their bisectors) and the hard planes hold.
void solveLeastPenetration(std::span<const HalfPlane> planes, std::size_t hard, std::size_t firstFailed,
                           float maxSpeed, std::vector<HalfPlane>& projected, Vec2f& result) {
  float worst = 0.0f;
  for (std::size_t i = firstFailed; i < planes.size(); ++i) {
    if (penetration(planes[i], result) <= worst) continue;
    const HalfPlane& hi = planes[i];
    projected.assign(planes.begin(), planes.begin() + std::min(hard, i));
    for (std::size_t j = hard; j < i; ++j) {
      // pen_j(v) <= pen_i(v)  <=>  v . (n_j - n_i) >= p_j . n_j - p_i . n_i
      const HalfPlane& hj = planes[j];
      const Vec2f m = hj.normal - hi.normal;
      const float len = m.norm();
      if (len < kEps) continue;  // same direction: no bisector, plane i is the binding one
      const Vec2f normal = m / len;
      projected.push_back({normal * ((hj.point.dot(hj.normal) - hi.point.dot(hi.normal)) / len), normal});
    }
    const Vec2f previous = result;
    if (solvePlanar(projected, maxSpeed, hi.normal, true, result) < projected.size()) result = previous;
    worst = penetration(hi, result);
  }
}

}  // namespace

Vec2f solveOrcaProgram(std::span<const HalfPlane> planes, std::size_t hard, const Vec2f& preferred, float maxSpeed,
                       std::vector<HalfPlane>& scratch) {
  Vec2f v;
  const std::size_t done = solvePlanar(planes, maxSpeed, preferred, false, v);
  if (done < planes.size()) solveLeastPenetration(planes, hard, done, maxSpeed, scratch, v);
  return v;
}

void OrcaSolver::computeVelocities(const Agents& agents, const StaticObstacles& obstacles, const OrcaParams& params,
                                   float dt, std::span<Vec2f> out, const lookahead::DiscreteLookahead* lookahead,
                                   std::span<const std::uint8_t> skip) {
  const std::size_t n = agents.size();
  if (n == 0) return;
  grid_.build(agents.position, params.neighbourDist);
  const std::span<const std::uint32_t> order = grid_.cellOrder();
  const std::span<const Vec2f> pos = grid_.sortedPoints();
  slots_.resize(n);
  parallelFor(
      0, n,
      [&](std::size_t k) {
        const std::uint32_t j = order[k];
        slots_[k] = {agents.velocity[j], agents.radius[j], agents.model[j] == AgentModel::Orca ? 0.5f : 1.0f};
      },
      4096);
  const Slot* slot = slots_.data();
  const int ny = grid_.cellsY();
  const std::size_t cellsX = static_cast<std::size_t>(grid_.cellsX());
  const std::size_t maxNeighbours = static_cast<std::size_t>(std::max(0, params.maxNeighbours));
  const float invTau = 1.0f / params.timeHorizon, invTauObst = 1.0f / params.timeHorizonObst, invDt = 1.0f / dt;
  // The grid's cells are at least neighbourDist wide, so a cell's stencil holds the neighbours of
  // its agents (three contiguous slot ranges).
  const float range2 = params.neighbourDist * params.neighbourDist;
  const std::size_t grain = std::max<std::size_t>(1, static_cast<std::size_t>(ny) * 1024 / n);
  auto closer = [](const Neighbour& a, const Neighbour& b) { return a.d2 < b.d2 || (a.d2 == b.d2 && a.id < b.id); };

  tbb::parallel_for(tbb::blocked_range<int>(0, ny, grain), [&](const tbb::blocked_range<int>& rows) {
    Scratch& s = scratch_.local();
    grid_.forEachCellInRows(
        rows.begin(), rows.end(), [&](std::uint32_t first, std::uint32_t last, const NeighbourGrid::Stencil& st) {
          // Agent k's velocity, with `far` its lookahead constraints (null: none).
          const auto solve = [&](std::uint32_t k, const std::vector<HalfPlane>* far) {
            const std::size_t i = order[k];
            const Vec2f xi = pos[k], vi = slot[k].velocity;
            const float ri = slot[k].radius, maxSpeed = agents.maxSpeed[i];
            s.planes.clear();
            // Obstacle planes first: they stay hard in the infeasible case. With v_opt = 0 (sec. 6) the
            // closest point of VO^tau_{i|edge} to the origin is the closest point c of the grown edge,
            // scaled by 1/tau; the segment lies beyond the line through it, so |v dt| stays short of it.
            const float obstRange = maxSpeed * params.timeHorizonObst + ri;
            if (!obstacles.empty()) {
              obstacles.forEachEdgeNear(xi, [&](const Vec2f& a, const Vec2f& b) {
                const Vec2f e = b - a;
                const float len2 = e.squaredNorm();
                const float t = len2 > 0.0f ? std::clamp((xi - a).dot(e) / len2, 0.0f, 1.0f) : 0.0f;
                const Vec2f toEdge = a + t * e - xi;
                const float dist = toEdge.norm();
                if (dist >= obstRange || dist < 1e-6f) return;
                const Vec2f dir = toEdge / dist;
                // Already overlapping: leave within one step (sec. 5.1's rule, for an obstacle).
                const float allowed = dist > ri ? (dist - ri) * invTauObst : (dist - ri) * invDt;
                s.planes.push_back({dir * allowed, -dir});
              });
            }
            const std::size_t hard = s.planes.size();

            // The maxNeighbours closest agents within neighbourDist, ties by index (deterministic). Each
            // row of the stencil's distances is computed in one vectorisable pass; the list is only touched
            // by candidates closer than its current last entry (or within range while it is short).
            // The agent's own row of cells first: it holds the closest candidates, so the list's
            // threshold falls soonest (the list does not depend on the order).
            s.nearest.clear();
            if (maxNeighbours > 0) {
              float threshold = range2;  // candidates beyond it cannot enter the list
              const int ownRow = static_cast<int>(st.cell / cellsX) - st.y0;
              for (int t = 0; t < st.count; ++t) {
                const int q = (ownRow + t) % st.count;
                const std::uint32_t lo = st.lo[q], count = st.hi[q] - lo;
                // Padded to whole blocks of kBlock with distances no candidate has.
                const std::uint32_t padded = (count + kBlock - 1) / kBlock * kBlock;
                s.distances.resize(std::max<std::size_t>(s.distances.size(), padded));
                float* d2 = s.distances.data();
                const Vec2f* p = pos.data() + lo;
                for (std::uint32_t m = 0; m < count; ++m) {
                  const float ex = p[m].x() - xi.x(), ey = p[m].y() - xi.y();
                  d2[m] = ex * ex + ey * ey;
                }
                std::fill(d2 + count, d2 + padded, std::numeric_limits<float>::infinity());
                // The candidates under the threshold, a block at a time as a bit mask (one vector
                // compare instead of a hard-to-predict branch per candidate); the threshold may fall
                // within a block, so each is tested again.
                for (std::uint32_t block = 0; block < padded; block += kBlock) {
                  std::uint32_t below = 0;
                  for (std::uint32_t b = 0; b < kBlock; ++b)
                    below |= static_cast<std::uint32_t>(d2[block + b] <= threshold) << b;
                  for (; below != 0; below &= below - 1) {
                    const std::uint32_t m = block + static_cast<std::uint32_t>(std::countr_zero(below));
                    if (d2[m] > threshold) continue;
                    const std::uint32_t j = lo + m;
                    if (d2[m] >= range2 || j == k) continue;
                    const Neighbour entry{d2[m], order[j], j};
                    if (s.nearest.size() == maxNeighbours) {
                      if (!closer(entry, s.nearest.back())) continue;
                      s.nearest.back() = entry;
                    } else {
                      s.nearest.push_back(entry);
                    }
                    for (std::size_t at = s.nearest.size() - 1; at > 0 && closer(s.nearest[at], s.nearest[at - 1]); --at)
                      std::swap(s.nearest[at], s.nearest[at - 1]);
                    if (s.nearest.size() == maxNeighbours) threshold = s.nearest.back().d2;
                  }
                }
              }
            }

            for (const Neighbour& nb : s.nearest) {
              // Reciprocity: half the avoidance each; all of it towards agents that do not run ORCA.
              s.planes.push_back(orcaHalfPlane(pos[nb.slot] - xi, vi - slot[nb.slot].velocity, ri + slot[nb.slot].radius,
                                               invTau, invDt, vi, slot[nb.slot].share, i < nb.id ? -1.0f : 1.0f));
            }
            if (far != nullptr) s.planes.insert(s.planes.end(), far->begin(), far->end());
            out[i] = solveOrcaProgram(s.planes, hard, agents.preferredVelocity[i], maxSpeed, s.projected);
          };
          // Agents that look ahead go in batches of the cell's neighbours, which share one
          // traversal of the lookahead's tree (discrete_lookahead.hpp).
          std::array<lookahead::LookaheadAgent, lookahead::kLookaheadBatch> batch;
          std::array<std::uint32_t, lookahead::kLookaheadBatch> batchSlot;
          std::size_t batched = 0;
          s.far.resize(lookahead::kLookaheadBatch);
          const auto flush = [&] {
            for (std::size_t a = 0; a < batched; ++a) s.far[a].clear();
            lookahead::appendLookaheadPlanes(*lookahead, std::span(batch.data(), batched), invTau, s.far);
            for (std::size_t a = 0; a < batched; ++a) solve(batchSlot[a], &s.far[a]);
            batched = 0;
          };
          for (std::uint32_t k = first; k < last; ++k) {
            if (slot[k].share != 0.5f) continue;  // not an ORCA agent
            const std::size_t i = order[k];
            if (!skip.empty() && skip[i]) continue;
            if (lookahead == nullptr || lookahead->depth[i] == 0) {
              solve(k, nullptr);
              continue;
            }
            batch[batched] = {static_cast<std::uint32_t>(i), pos[k], slot[k].velocity, slot[k].radius};
            batchSlot[batched++] = k;
            if (batched == batch.size()) flush();
          }
          if (batched > 0) flush();
        });
  });
}

}  // namespace msim::crowd
