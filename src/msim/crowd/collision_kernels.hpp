#pragma once
// The inner loops of pairwise collision resolution (collision_resolution.cpp), on the cell-ordered
// structure-of-arrays copy of the agents: Jacobi pushes (scalar and AVX2, eight neighbours at a
// time), the Gauss-Seidel pair projections (over slot ranges, eight at a time, and over a list of
// partners), and the hashed direction that separates coincident agents. Internal to the resolver;
// kept apart so that file holds the algorithm, this one the arithmetic.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <cstdint>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include "msim/crowd/agents.hpp"

namespace msim::crowd::collision_kernels {

// Unit direction pushing i away from j when they coincide: a direction hashed from the pair, with
// opposite signs for i and j, so the pushes still cancel and the result stays deterministic.
inline Vec2f coincidentDirection(std::size_t i, std::size_t j) {
  const std::uint64_t lo = std::min(i, j), hi = std::max(i, j);
  std::uint64_t h = lo * 0x9E3779B97F4A7C15ull ^ (hi + 0x632BE59BD9B4E019ull);
  h ^= h >> 31;
  h *= 0xD6E8FEB86659FD93ull;
  h ^= h >> 32;
  const float angle = static_cast<float>(h & 0xFFFFFF) * (6.2831853f / 16777216.0f);
  const float sign = i < j ? 1.0f : -1.0f;
  return sign * Vec2f(std::cos(angle), std::sin(angle));
}

// Slack after the last slot so the 8-wide kernels may read past the end (padding agents are far
// away and never within range).
constexpr std::size_t kPad = 8;


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

// 1 / sqrt(x) for x > 0: the hardware estimate and one Newton step (relative error ~1e-7, a third
// of the cost of sqrt + div).
inline float inverseSqrt(float x) {
#if defined(__AVX2__)
  const float est = _mm_cvtss_f32(_mm_rsqrt_ss(_mm_set_ss(x)));
  return 0.5f * est * (3.0f - x * est * est);
#else
  return 1.0f / std::sqrt(x);
#endif
}

// The cell-ordered slots a Gauss-Seidel sweep reads and moves.
struct SweepSlots {
  float* x;
  float* y;
  // Per slot: the largest squared distance from its bucketed position it has been at in the sweep.
  float* far;
  const float* bucketX;  // positions when bucketed (padded like x and y)
  const float* bucketY;
  const float* radius;
  const float* yield;
  const std::uint32_t* agent;  // agent index (hashes the direction of coincident pairs)
};

// Corrections of agent i against its coincident partners (closer than 1e-7 target) among the
// slots forEachPartner(f) enumerates, along a direction hashed from the pair; moves the partners
// and returns i's share. Rare, and out of line so that the loops of projectPartners and
// projectRanges keep their values in registers (a call there spills them).
template <typename ForEachPartner, typename OnPartner>
[[gnu::cold, gnu::noinline]] Vec2f coincidentCorrections(const SweepSlots& a, std::uint32_t i,
                                                          const ForEachPartner& forEachPartner, float s,
                                                          const OnPartner& onPartner) {
  Vec2f share = Vec2f::Zero();
  const float xi = a.x[i], yi = a.y[i], ri = a.radius[i], yieldI = a.yield[i];
  forEachPartner([&](std::uint32_t j) {
    const float ex = xi - a.x[j], ey = yi - a.y[j];
    const float target = s * (ri + a.radius[j]);
    const float d2 = ex * ex + ey * ey;
    if (j == i || d2 > 1e-14f * target * target) return;
    const Vec2f c = (target - std::sqrt(d2)) * coincidentDirection(a.agent[i], a.agent[j]);
    const float si = yieldI < 0.75f ? a.yield[j] : 0.0f;
    const float sj = yieldI * (2.0f - 2.0f * a.yield[j]);
    share += si * c;
    a.x[j] -= sj * c.x();
    a.y[j] -= sj * c.y();
    const float lx = a.x[j] - a.bucketX[j], ly = a.y[j] - a.bucketY[j];
    a.far[j] = std::max(a.far[j], lx * lx + ly * ly);
    onPartner(j);
  });
  return share;
}

// The end of agent i's projections: its coincident partners (rare, out of line), then its own
// shares (dx, dy) applied together.
template <typename ForEachPartner, typename OnPartner>
inline void applyShares(const SweepSlots& a, std::uint32_t i, float dx, float dy, bool coincident,
                        const ForEachPartner& forEachPartner, float s, const OnPartner& onPartner) {
  if (coincident) [[unlikely]] {
    const Vec2f share = coincidentCorrections(a, i, forEachPartner, s, onPartner);
    dx += share.x();
    dy += share.y();
  }
  if (dx == 0.0f && dy == 0.0f) return;
  a.x[i] += dx;
  a.y[i] += dy;
  const float lx = a.x[i] - a.bucketX[i], ly = a.y[i] - a.bucketY[i];
  a.far[i] = std::max(a.far[i], lx * lx + ly * ly);
}

// Gauss-Seidel projections of agent i's pairs with the partners forEachPartner(f) enumerates
// (never i itself): each pair closer than target = s (r_i + r_j) is pushed apart to target along
// its centre line, i taking si = yield_j (0 if i is scripted) of the correction and j taking
// sj = yield_i (2 - 2 yield_j) (0 if j is scripted): equal and opposite for two movable agents.
// Each j is moved in place as it comes; i's shares are taken from its position at the start and
// applied together at the end (coincident partners last).
template <typename ForEachPartner, typename OnPartner>
inline void projectPartners(const SweepSlots& a, std::uint32_t i, const ForEachPartner& forEachPartner, float s,
                            const OnPartner& onPartner) {
  // The slot arrays do not overlap: without restrict every store would force the loads again.
  float* __restrict x = a.x;
  float* __restrict y = a.y;
  float* __restrict far = a.far;
  const float* __restrict bucketX = a.bucketX;
  const float* __restrict bucketY = a.bucketY;
  const float* __restrict radius = a.radius;
  const float* __restrict yield = a.yield;
  const float xi = x[i], yi = y[i], ri = radius[i], yieldI = yield[i];
  const bool movableI = yieldI < 0.75f;  // yield 1/2: movable, 1: scripted
  float dx = 0.0f, dy = 0.0f;
  bool coincident = false;
  forEachPartner([&](std::uint32_t j) {
    const float xj = x[j], yj = y[j];
    const float ex = xi - xj, ey = yi - yj;
    const float target = s * (ri + radius[j]);
    const float d2 = ex * ex + ey * ey, t2 = target * target;
    if (d2 >= t2) return;
    if (!(d2 > 1e-14f * t2)) [[unlikely]] {
      coincident = true;
      return;
    }
    const float f = target * inverseSqrt(d2) - 1.0f;  // (target - dist) / dist
    const float si = movableI ? yield[j] : 0.0f;
    const float sj = yieldI * (2.0f - 2.0f * yield[j]);
    dx += si * f * ex;
    dy += si * f * ey;
    if (sj > 0.0f) {
      x[j] = xj - sj * f * ex;
      y[j] = yj - sj * f * ey;
      const float lx = x[j] - bucketX[j], ly = y[j] - bucketY[j];
      far[j] = std::max(far[j], lx * lx + ly * ly);
    }
    onPartner(j);
  });
  applyShares(a, i, dx, dy, coincident, forEachPartner, s, onPartner);
}

// Gauss-Seidel projections of agent i against every slot of the ranges [lo[q], hi[q]), q < count
// (no j == i among them): projectPartners over those slots, the partners found by testing the
// distances at the current positions. i's shares are taken from its start position and applied at
// the end, so its partners do not depend on each other and eight are projected at a time (AVX2;
// reads up to 7 slots past a range, masked off). onPartner(j) for every partner pushed (the
// local sweeps list the agents they moved; whole sweeps need not).
struct NoPartnerCallback {
  void operator()(std::uint32_t) const {}
};
template <typename OnPartner = NoPartnerCallback>
inline void projectRanges(const SweepSlots& a, std::uint32_t i, const std::uint32_t* lo, const std::uint32_t* hi,
                          int count, float s, const OnPartner& onPartner = {}) {
  auto ranges = [&](const auto& f) {
    for (int r = 0; r < count; ++r)
      for (std::uint32_t j = lo[r]; j < hi[r]; ++j) f(j);
  };
#if defined(__AVX2__)
  const float xi = a.x[i], yi = a.y[i], ri = a.radius[i], yieldI = a.yield[i];
  const bool movableI = yieldI < 0.75f;
  bool coincident = false;
  float* __restrict x = a.x;
  float* __restrict y = a.y;
  float* __restrict far = a.far;
  const __m256 xv = _mm256_set1_ps(xi), yv = _mm256_set1_ps(yi), rv = _mm256_set1_ps(ri), sv = _mm256_set1_ps(s);
  const __m256 siMask = movableI ? _mm256_castsi256_ps(_mm256_set1_epi32(-1)) : _mm256_setzero_ps();
  const __m256 yieldIv = _mm256_set1_ps(yieldI), two = _mm256_set1_ps(2.0f), one = _mm256_set1_ps(1.0f);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  __m256 ax = _mm256_setzero_ps(), ay = _mm256_setzero_ps();
  for (int r = 0; r < count; ++r)
    for (std::uint32_t j = lo[r]; j < hi[r]; j += 8) {
      const __m256 valid =
          _mm256_castsi256_ps(_mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(hi[r] - j)), lane));
      const __m256 xj = _mm256_loadu_ps(x + j), yj = _mm256_loadu_ps(y + j);
      const __m256 ex = _mm256_sub_ps(xv, xj), ey = _mm256_sub_ps(yv, yj);
      const __m256 d2 = _mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey));
      const __m256 target = _mm256_mul_ps(sv, _mm256_add_ps(rv, _mm256_loadu_ps(a.radius + j)));
      const __m256 t2 = _mm256_mul_ps(target, target);
      const __m256 in = _mm256_and_ps(valid, _mm256_cmp_ps(d2, t2, _CMP_LT_OQ));
      if (_mm256_testz_ps(in, in)) continue;
      const __m256 apart = _mm256_cmp_ps(d2, _mm256_mul_ps(_mm256_set1_ps(1e-14f), t2), _CMP_GT_OQ);
      coincident |= !_mm256_testz_ps(in, _mm256_andnot_ps(apart, in));
      const __m256 m = _mm256_and_ps(in, apart);
      // (target - dist) / dist with 1 / dist as in inverseSqrt (same rounding as projectPartners).
      const __m256 est = _mm256_rsqrt_ps(d2);
      const __m256 inv = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), est),
                                       _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_mul_ps(d2, est), est)));
      const __m256 f = _mm256_sub_ps(_mm256_mul_ps(target, inv), one);
      const __m256 yieldJ = _mm256_loadu_ps(a.yield + j);
      const __m256 si = _mm256_and_ps(siMask, yieldJ);
      const __m256 sj = _mm256_mul_ps(yieldIv, _mm256_sub_ps(two, _mm256_mul_ps(two, yieldJ)));
      ax = _mm256_add_ps(ax, _mm256_and_ps(m, _mm256_mul_ps(_mm256_mul_ps(si, f), ex)));
      ay = _mm256_add_ps(ay, _mm256_and_ps(m, _mm256_mul_ps(_mm256_mul_ps(si, f), ey)));
      // The partners move now (in place), and their farthest distance from the bucketed positions.
      const __m256 nx = _mm256_sub_ps(xj, _mm256_mul_ps(_mm256_mul_ps(sj, f), ex));
      const __m256 ny = _mm256_sub_ps(yj, _mm256_mul_ps(_mm256_mul_ps(sj, f), ey));
      const __m256 lx = _mm256_sub_ps(nx, _mm256_loadu_ps(a.bucketX + j));
      const __m256 ly = _mm256_sub_ps(ny, _mm256_loadu_ps(a.bucketY + j));
      const __m256 e2 = _mm256_add_ps(_mm256_mul_ps(lx, lx), _mm256_mul_ps(ly, ly));
      const __m256 farJ = _mm256_loadu_ps(far + j);
      // Only the moved lanes are written, one at a time (usually a few): lanes past the range may
      // belong to rows other tasks move, and whole 8-wide stores, blended or masked, were slower
      // (the next agent's loads overlap them and wait for them; 100k circle: collisions 10% slower).
      alignas(32) float lanes[3][8];
      _mm256_store_ps(lanes[0], nx);
      _mm256_store_ps(lanes[1], ny);
      _mm256_store_ps(lanes[2], _mm256_max_ps(farJ, e2));
      for (unsigned bits = static_cast<unsigned>(_mm256_movemask_ps(m)); bits != 0; bits &= bits - 1) {
        const unsigned l = static_cast<unsigned>(__builtin_ctz(bits));
        x[j + l] = lanes[0][l];
        y[j + l] = lanes[1][l];
        far[j + l] = lanes[2][l];
        onPartner(j + l);
      }
    }
  applyShares(a, i, sum8(ax), sum8(ay), coincident, ranges, s, onPartner);
#else
  projectPartners(a, i, ranges, s, onPartner);
#endif
}
}  // namespace msim::crowd::collision_kernels
