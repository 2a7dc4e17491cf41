#pragma once
// The inner loops of pairwise collision resolution (collision_resolution.cpp), on the cell-ordered
// structure-of-arrays copy of the agents: Jacobi pushes and Gauss-Seidel pair projections, scalar
// and AVX2 (eight neighbours at a time), and the hashed direction that separates coincident
// agents. Internal to the resolver; kept apart so that file holds the algorithm, this one the
// arithmetic.
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

// Gauss-Seidel pair projections of agent i (at xi, yi, radius ri, yield yi_) against the slots
// [lo, hi), all after i in the processing order: each pair closer than target = s (r_i + r_j) is
// pushed apart to target, i taking si = yield_j (0 if i is scripted) of the correction and j
// taking sj = yield_i (2 - 2 yield_j) (0 if j is scripted): equal and opposite for two movable
// agents. j is updated in place (masked loads and stores: no slot outside the range is touched);
// i's share is summed into ax, ay, and the lengths moved into path (j) and pathI. Returns the
// lanes of coincident pairs of the last batch via `close` (handled by the caller, rare).
inline bool projectAvx(float* xs, float* ys, const float* rad, const float* yield, float* path, std::uint32_t lo,
                       std::uint32_t hi, float xi, float yi, float ri, float yieldI, bool movableI, float s,
                       __m256& ax, __m256& ay, __m256& pathI, int& close) {
  const __m256 xv = _mm256_set1_ps(xi), yv = _mm256_set1_ps(yi), rv = _mm256_set1_ps(ri), sv = _mm256_set1_ps(s);
  const __m256 eps = _mm256_set1_ps(1e-14f), one = _mm256_set1_ps(1.0f), two = _mm256_set1_ps(2.0f);
  const __m256 movI = movableI ? _mm256_castsi256_ps(_mm256_set1_epi32(-1)) : _mm256_setzero_ps();
  const __m256 yI = _mm256_set1_ps(yieldI);
  const __m256i lane = _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7);
  bool changed = false;
  for (std::uint32_t j = lo; j < hi; j += 8) {
    const __m256i valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(hi - j)), lane);
    const __m256 xj = _mm256_maskload_ps(xs + j, valid), yj = _mm256_maskload_ps(ys + j, valid);
    const __m256 ex = _mm256_sub_ps(xv, xj), ey = _mm256_sub_ps(yv, yj);
    const __m256 d2 = _mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey));
    const __m256 target = _mm256_mul_ps(sv, _mm256_add_ps(rv, _mm256_maskload_ps(rad + j, valid)));
    const __m256 t2 = _mm256_mul_ps(target, target);
    const __m256 in = _mm256_and_ps(_mm256_castsi256_ps(valid), _mm256_cmp_ps(d2, t2, _CMP_LT_OQ));
    if (_mm256_testz_ps(in, in)) continue;
    const __m256 apart = _mm256_cmp_ps(d2, _mm256_mul_ps(eps, t2), _CMP_GT_OQ);
    close += __builtin_popcount(static_cast<unsigned>(_mm256_movemask_ps(_mm256_andnot_ps(apart, in))));
    const __m256 est = _mm256_rsqrt_ps(d2);
    const __m256 inv = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), est),
                                     _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_mul_ps(d2, est), est)));
    const __m256 m = _mm256_and_ps(in, apart);
    // The whole correction along e: (target / dist - 1) e, of length target - dist.
    const __m256 f = _mm256_and_ps(m, _mm256_sub_ps(_mm256_mul_ps(target, inv), one));
    const __m256 yJ = _mm256_maskload_ps(yield + j, valid);
    const __m256 si = _mm256_and_ps(movI, yJ);
    const __m256 sj = _mm256_mul_ps(yI, _mm256_sub_ps(two, _mm256_mul_ps(two, yJ)));
    const __m256 cx = _mm256_mul_ps(f, ex), cy = _mm256_mul_ps(f, ey);
    const __m256 len = _mm256_sub_ps(target, _mm256_mul_ps(d2, inv));  // target - dist
    ax = _mm256_add_ps(ax, _mm256_mul_ps(si, cx));
    ay = _mm256_add_ps(ay, _mm256_mul_ps(si, cy));
    pathI = _mm256_add_ps(pathI, _mm256_and_ps(m, _mm256_mul_ps(si, len)));
    const __m256 moveJ = _mm256_and_ps(m, _mm256_cmp_ps(sj, _mm256_setzero_ps(), _CMP_GT_OQ));
    changed |= (movableI && !_mm256_testz_ps(m, m)) || !_mm256_testz_ps(moveJ, moveJ);
    _mm256_maskstore_ps(xs + j, valid, _mm256_sub_ps(xj, _mm256_mul_ps(sj, cx)));
    _mm256_maskstore_ps(ys + j, valid, _mm256_sub_ps(yj, _mm256_mul_ps(sj, cy)));
    const __m256 pj = _mm256_maskload_ps(path + j, valid);
    _mm256_maskstore_ps(path + j, valid, _mm256_add_ps(pj, _mm256_and_ps(m, _mm256_mul_ps(sj, len))));
  }
  return changed;
}

// Broadcast of lane `l` of v.
inline __m256 lane(__m256 v, int l) { return _mm256_permutevar8x32_ps(v, _mm256_set1_epi32(l)); }
// Sum of the lanes of v in every lane.
inline __m256 hsumAll(__m256 v) {
  v = _mm256_add_ps(v, _mm256_permute2f128_ps(v, v, 1));
  v = _mm256_add_ps(v, _mm256_permute_ps(v, 0b01001110));
  return _mm256_add_ps(v, _mm256_permute_ps(v, 0b10110001));
}

// One block of up to 8 candidate slots held in registers (positions, radii, yields, the lengths
// moved), loaded once per cell and stored back once.
struct Block {
  __m256i valid;
  __m256 x, y, r, w, path;
  std::uint32_t lo;
  void load(const float* xs, const float* ys, const float* rad, const float* yield, const float* p, std::uint32_t from,
            std::uint32_t count) {
    lo = from;
    valid = _mm256_cmpgt_epi32(_mm256_set1_epi32(static_cast<int>(count)), _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7));
    x = _mm256_maskload_ps(xs + from, valid);
    y = _mm256_maskload_ps(ys + from, valid);
    r = _mm256_maskload_ps(rad + from, valid);
    w = _mm256_maskload_ps(yield + from, valid);
    path = _mm256_maskload_ps(p + from, valid);
  }
  void store(float* xs, float* ys, float* p) const {
    _mm256_maskstore_ps(xs + lo, valid, x);
    _mm256_maskstore_ps(ys + lo, valid, y);
    _mm256_maskstore_ps(p + lo, valid, path);
  }
};

// projectAvx with the candidates in registers: agent i (broadcast in xv, yv, rv, yieldI; movI
// all ones when it may move) against the lanes `use` of block b. Returns whether anything moved;
// coincident pairs (rare) are done with their hashed directions through a scalar patch.
inline bool projectBlock(Block& b, __m256 use, __m256 xv, __m256 yv, __m256 rv, __m256 yI, __m256 movI, __m256 sv,
                         std::uint32_t i, const std::uint32_t* agent, __m256& ax, __m256& ay, __m256& pathI) {
  const __m256 one = _mm256_set1_ps(1.0f), two = _mm256_set1_ps(2.0f);
  const __m256 ex = _mm256_sub_ps(xv, b.x), ey = _mm256_sub_ps(yv, b.y);
  const __m256 d2 = _mm256_add_ps(_mm256_mul_ps(ex, ex), _mm256_mul_ps(ey, ey));
  const __m256 target = _mm256_mul_ps(sv, _mm256_add_ps(rv, b.r));
  const __m256 t2 = _mm256_mul_ps(target, target);
  const __m256 in = _mm256_and_ps(use, _mm256_cmp_ps(d2, t2, _CMP_LT_OQ));
  if (_mm256_testz_ps(in, in)) return false;
  const __m256 apart = _mm256_cmp_ps(d2, _mm256_mul_ps(_mm256_set1_ps(1e-14f), t2), _CMP_GT_OQ);
  const __m256 est = _mm256_rsqrt_ps(d2);
  const __m256 inv = _mm256_mul_ps(_mm256_mul_ps(_mm256_set1_ps(0.5f), est),
                                   _mm256_sub_ps(_mm256_set1_ps(3.0f), _mm256_mul_ps(_mm256_mul_ps(d2, est), est)));
  const __m256 m = _mm256_and_ps(in, apart);
  const __m256 f = _mm256_and_ps(m, _mm256_sub_ps(_mm256_mul_ps(target, inv), one));
  __m256 cx = _mm256_mul_ps(f, ex), cy = _mm256_mul_ps(f, ey);
  __m256 len = _mm256_and_ps(m, _mm256_sub_ps(target, _mm256_mul_ps(d2, inv)));
  const int coincident = _mm256_movemask_ps(_mm256_andnot_ps(apart, in));
  if (coincident != 0) {
    alignas(32) float lx[8], ly[8], ll[8], lt[8], ld[8];
    _mm256_store_ps(lx, cx);
    _mm256_store_ps(ly, cy);
    _mm256_store_ps(ll, len);
    _mm256_store_ps(lt, target);
    _mm256_store_ps(ld, d2);
    for (int l = 0; l < 8; ++l)
      if (coincident >> l & 1) {
        const Vec2f dir = coincidentDirection(agent[i], agent[b.lo + l]);
        ll[l] = lt[l] - std::sqrt(ld[l]);
        lx[l] = ll[l] * dir.x();
        ly[l] = ll[l] * dir.y();
      }
    cx = _mm256_load_ps(lx);
    cy = _mm256_load_ps(ly);
    len = _mm256_load_ps(ll);
  }
  const __m256 si = _mm256_and_ps(movI, b.w);
  const __m256 sj = _mm256_mul_ps(yI, _mm256_sub_ps(two, _mm256_mul_ps(two, b.w)));
  ax = _mm256_add_ps(ax, _mm256_mul_ps(si, cx));
  ay = _mm256_add_ps(ay, _mm256_mul_ps(si, cy));
  pathI = _mm256_add_ps(pathI, _mm256_mul_ps(si, len));
  b.x = _mm256_sub_ps(b.x, _mm256_mul_ps(sj, cx));
  b.y = _mm256_sub_ps(b.y, _mm256_mul_ps(sj, cy));
  b.path = _mm256_add_ps(b.path, _mm256_mul_ps(sj, len));
  const __m256 movesJ = _mm256_and_ps(in, _mm256_cmp_ps(sj, _mm256_setzero_ps(), _CMP_GT_OQ));
  return !_mm256_testz_ps(_mm256_and_ps(in, movI), _mm256_and_ps(in, movI)) || !_mm256_testz_ps(movesJ, movesJ);
}

inline float sum8(__m256 v) {
  alignas(32) float l[8];
  _mm256_store_ps(l, v);
  return ((l[0] + l[1]) + (l[2] + l[3])) + ((l[4] + l[5]) + (l[6] + l[7]));
}
#endif

// Scalar projectAvx (no AVX2), and the coincident pairs of the AVX2 path (`coincidentOnly`).
inline bool projectScalar(float* xs, float* ys, const float* rad, const float* yield, float* path,
                          const std::uint32_t* agent, std::uint32_t lo, std::uint32_t hi, std::uint32_t i, float xi,
                          float yi, float ri, float yieldI, bool movableI, float s, bool coincidentOnly, float& dx,
                          float& dy, float& pathI) {
  bool changed = false;
  for (std::uint32_t j = lo; j < hi; ++j) {
    const float ex = xi - xs[j], ey = yi - ys[j];
    const float target = s * (ri + rad[j]);
    const float d2 = ex * ex + ey * ey, t2 = target * target;
    if (d2 >= t2) continue;
    const bool coincident = !(d2 > 1e-14f * t2);
    if (coincident != coincidentOnly) continue;
    const float si = movableI ? yield[j] : 0.0f;
    const float sj = yieldI * (2.0f - 2.0f * yield[j]);
    float cx, cy, len;
    if (coincident) {
      const Vec2f dir = coincidentDirection(agent[i], agent[j]);
      len = target - std::sqrt(d2);
      cx = len * dir.x();
      cy = len * dir.y();
    } else {
      const float dist = std::sqrt(d2);
      const float f = (target - dist) / dist;
      len = target - dist;
      cx = f * ex;
      cy = f * ey;
    }
    dx += si * cx;
    dy += si * cy;
    pathI += si * len;
    xs[j] -= sj * cx;
    ys[j] -= sj * cy;
    path[j] += sj * len;
    changed |= si > 0.0f || sj > 0.0f;
  }
  return changed;
}
}  // namespace msim::crowd::collision_kernels
