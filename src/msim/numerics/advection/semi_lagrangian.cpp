#include "msim/numerics/advection/semi_lagrangian.hpp"

#include <algorithm>
#include <cmath>
#include <type_traits>

#if defined(__AVX2__)
#include <immintrin.h>
#endif

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// Tracing runs over chunks of a sample row in structure-of-arrays form: every stage is a short
// branch-free loop over the chunk, which the compiler vectorises (the per-sample version spent
// most of its time in scalar floor/clamp/index arithmetic).
constexpr int kChunk = 64;

// Stencils of m points of one chunk: lower-corner index, per axis the step to the upper corner
// and the weight of the upper corner.
// 32-bit indices (fields hold fewer than 2^31 samples, see Feet) halve the index traffic and
// match the AVX2 gather.
template <typename T, int D>
struct ChunkStencil {
  std::int32_t base[kChunk];
  std::int32_t up[D][kChunk];
  T t[D][kChunk];
};

// FieldLayout::stencil for m sample-space points s[a][q] (sample c sits at s = c), in T
// arithmetic instead of double world coordinates.
template <typename T, int D>
void locateChunk(const SampleLattice<D>& L, const T (*s)[kChunk], int m, ChunkStencil<T, D>& st) {
  for (int q = 0; q < m; ++q) st.base[q] = 0;
  for (int a = 0; a < D; ++a) {
    const int n = L.size[a];
    const auto stride = static_cast<std::int32_t>(L.stride[a]), step = static_cast<std::int32_t>(L.step[a]),
               wrapStep = static_cast<std::int32_t>(L.wrapStep[a]);
    if (n < 2) {
      for (int q = 0; q < m; ++q) {
        st.up[a][q] = step;
        st.t[a][q] = T(0);
      }
    } else if (L.periodic[a]) {
      const int period = L.period[a];
      const T p = T(period), far = T(1 << 30);  // keeps the integer conversion defined
      for (int q = 0; q < m; ++q) {
        T x = std::isfinite(s[a][q]) ? s[a][q] : T(0);  // a bad position must never index outside
        x = std::clamp(x, -far, far);
        const T fl = std::floor(x);
        int i0 = static_cast<int>(fl - p * std::floor(fl / p));
        i0 = std::clamp(i0, 0, period - 1);  // rounding of huge positions
        st.t[a][q] = x - fl;
        // On a periodic cell axis sample `period` wraps to 0; on a face axis it is a real sample.
        st.up[a][q] = i0 + 1 >= n ? wrapStep : step;
        st.base[q] += i0 * stride;
      }
    } else {
      // Positions are global sample coordinates, clamped at the global border; on a block of a
      // larger grid the local lower corner is the global one less `first`, clamped into the
      // block (a no-op while its ghost layers cover every stencil).
      const int globalSize = L.globalSize[a], first = L.first[a];
      const T last = T(globalSize - 1);
      for (int q = 0; q < m; ++q) {
        T x = std::isfinite(s[a][q]) ? s[a][q] : T(0);
        x = std::clamp(x, T(0), last);
        const int g0 = std::min(static_cast<int>(x), globalSize - 2);
        st.t[a][q] = x - T(g0);
        st.up[a][q] = step;
        st.base[q] += std::clamp(g0 - first, 0, n - 2) * stride;
      }
    }
  }
}

// out[q] = scale * D-linear interpolation of data at stencil q; lo/hi (optional) get the range of
// the corners read. Each axis blends (1-t) lower + t upper, exact at t = 0 and t = 1, so a foot on
// a sample returns its value bit for bit (solid samples rely on that). Scalar version: the
// tail of a chunk, double fields, and builds without AVX2.
template <typename T, int D, typename V>
void interpolateChunkScalar(const ChunkStencil<T, D>& st, const V* data, int first, int m, T scale, T* out, T* lo,
                            T* hi) {
  for (int q = first; q < m; ++q) {
    T v[1 << D];
    for (int k = 0; k < (1 << D); ++k) {
      std::ptrdiff_t o = st.base[q];
      for (int a = 0; a < D; ++a) o += (k >> a) & 1 ? st.up[a][q] : 0;
      v[k] = static_cast<T>(data[o]);
    }
    if (lo) {
      lo[q] = *std::min_element(v, v + (1 << D));
      hi[q] = *std::max_element(v, v + (1 << D));
    }
    for (int a = 0; a < D; ++a)
      for (int k = 0; k < (1 << (D - 1 - a)); ++k) {
        const T t = st.t[a][q];
#if defined(__FMA__)
        // Rounded as the AVX2 path rounds: which samples of a row take this tail depends on where
        // the row starts, and a block of a split grid must match the whole grid bit for bit.
        v[k] = std::fma(t, v[2 * k + 1], (T(1) - t) * v[2 * k]);
#else
        v[k] = (T(1) - t) * v[2 * k] + t * v[2 * k + 1];
#endif
      }
    out[q] = scale * v[0];
  }
}

template <typename T, int D, typename V>
void interpolateChunk(const ChunkStencil<T, D>& st, const V* data, int m, T scale, T* out, T* lo = nullptr,
                      T* hi = nullptr) {
  int q = 0;
#if defined(__AVX2__)
  // GCC does not vectorise the corner loads on its own (gathers are off in its generic tuning);
  // with explicit gathers 8 points cost 2^D gather instructions instead of 8 * 2^D scalar loads.
  if constexpr (std::is_same_v<T, float> && std::is_same_v<V, float>) {
    const __m256 one = _mm256_set1_ps(1.0f), sc = _mm256_set1_ps(scale);
    for (; q + 8 <= m; q += 8) {
      const __m256i base = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(st.base + q));
      __m256i up[D];
      for (int a = 0; a < D; ++a) up[a] = _mm256_loadu_si256(reinterpret_cast<const __m256i*>(st.up[a] + q));
      // Where the 8 stencils are consecutive samples of a row with equal corner steps (velocity at
      // the samples themselves, uniform flow), plain loads replace the gathers that bound this loop.
      const __m256i first = _mm256_set1_epi32(st.base[q]);
      __m256i same = _mm256_cmpeq_epi32(base, _mm256_add_epi32(first, _mm256_setr_epi32(0, 1, 2, 3, 4, 5, 6, 7)));
      for (int a = 0; a < D; ++a) same = _mm256_and_si256(same, _mm256_cmpeq_epi32(up[a], _mm256_set1_epi32(st.up[a][q])));
      const bool consecutive = _mm256_movemask_ps(_mm256_castsi256_ps(same)) == 0xFF;
      __m256 v[1 << D];
      for (int k = 0; k < (1 << D); ++k) {
        __m256i o = base;
        std::ptrdiff_t offset = st.base[q];
        for (int a = 0; a < D; ++a)
          if ((k >> a) & 1) {
            o = _mm256_add_epi32(o, up[a]);
            offset += st.up[a][q];
          }
        v[k] = consecutive ? _mm256_loadu_ps(data + offset) : _mm256_i32gather_ps(data, o, 4);
      }
      if (lo) {
        __m256 mn = v[0], mx = v[0];
        for (int k = 1; k < (1 << D); ++k) {
          mn = _mm256_min_ps(mn, v[k]);
          mx = _mm256_max_ps(mx, v[k]);
        }
        _mm256_storeu_ps(lo + q, mn);
        _mm256_storeu_ps(hi + q, mx);
      }
      for (int a = 0; a < D; ++a) {
        const __m256 t = _mm256_loadu_ps(st.t[a] + q), s = _mm256_sub_ps(one, t);
        for (int k = 0; k < (1 << (D - 1 - a)); ++k)
          v[k] = _mm256_fmadd_ps(t, v[2 * k + 1], _mm256_mul_ps(s, v[2 * k]));
      }
      _mm256_storeu_ps(out + q, _mm256_mul_ps(sc, v[0]));
    }
  }
#endif
  interpolateChunkScalar(st, data, q, m, scale, out, lo, hi);
}

// The MAC velocity in grid units: position g in cells from the domain origin, result in cells
// moved over dt (velocity * dt / dx), each component D-linear on its own face grid.
template <typename T, int D>
struct Displacement {
  SampleLattice<D> lattice[D];
  T offset[D][D];  // component a: sample-space position = g - offset[a]
  const float* data[D];
  T scale;

  Displacement(const MacGrid<D>& velocity, const AxisBoundaries<D>& boundaries, double dt,
               const BlockPlacement<D>& placement)
      : scale(static_cast<T>(dt / velocity.spec().dx)) {
    for (int a = 0; a < D; ++a) {
      const auto& g = velocity.component(a);
      lattice[a] = SampleLattice<D>(FieldLayout<D>::of(g, boundaries, placement));
      for (int b = 0; b < D; ++b) offset[a][b] = static_cast<T>(g.offset()[b]);
      data[a] = g.data().data();
    }
  }

  void operator()(const T (*g)[kChunk], int m, T (*u)[kChunk]) const {
    T s[D][kChunk];
    ChunkStencil<T, D> st;
    for (int a = 0; a < D; ++a) {
      for (int b = 0; b < D; ++b)
        for (int q = 0; q < m; ++q) s[b][q] = g[b][q] - offset[a][b];
      locateChunk(lattice[a], s, m, st);
      interpolateChunk(st, data[a], m, scale, u[a]);
    }
  }
};

template <typename T, int D>
void storeFeet(const SampleLattice<D>& L, const ChunkStencil<T, D>& st, int m, Feet<T, D>& feet, std::size_t at) {
  std::copy(st.base, st.base + m, feet.base.data() + at);
  std::uint8_t* wrap = feet.wrap.data() + at;
  for (int q = 0; q < m; ++q) wrap[q] = 0;
  for (int a = 0; a < D; ++a) {
    std::copy(st.t[a], st.t[a] + m, feet.t[a].data() + at);
    for (int q = 0; q < m; ++q) wrap[q] |= static_cast<std::uint8_t>((st.up[a][q] != L.step[a]) << a);
  }
}

// Whether any corner of stencil q is solid.
template <typename T, int D>
bool readsSolid(const ChunkStencil<T, D>& st, int q, const std::uint8_t* solid) {
  for (int k = 0; k < (1 << D); ++k) {
    std::ptrdiff_t o = st.base[q];
    for (int a = 0; a < D; ++a) o += (k >> a) & 1 ? st.up[a][q] : 0;
    if (solid[o]) return true;
  }
  return false;
}

}  // namespace

template <typename T, int D>
void traceFeet(const Grid<T, D>& field, const AxisBoundaries<D>& boundaries, const MacGrid<D>& velocity, double dt,
               BackTrace trace, const std::uint8_t* solid, Feet<T, D>& forward, Feet<T, D>& backward,
               std::uint8_t* touched, const BlockPlacement<D>& placement) {
  const SampleLattice<D> lattice(FieldLayout<D>::of(field, boundaries, placement));
  const Displacement<T, D> displacement(velocity, boundaries, dt, placement);
  T offset[D];
  for (int a = 0; a < D; ++a) offset[a] = static_cast<T>(field.offset()[a]);
  forward.resize(field.count());
  backward.resize(field.count());
  const IVec<D> size = field.size();
  std::size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= static_cast<std::size_t>(size[a]);
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, rows), [&](const tbb::blocked_range<std::size_t>& r) {
    T s[D][kChunk], g[D][kChunk], u[D][kChunk], uf[D][kChunk], ub[D][kChunk], p[D][kChunk];
    ChunkStencil<T, D> st;
    for (std::size_t row = r.begin(); row != r.end(); ++row) {
      int coord[D];
      std::size_t rest = row;
      for (int a = 1; a < D; ++a) {
        coord[a] = static_cast<int>(rest % static_cast<std::size_t>(size[a]));
        rest /= static_cast<std::size_t>(size[a]);
      }
      for (int i0 = 0; i0 < size[0]; i0 += kChunk) {
        const int m = std::min(kChunk, size[0] - i0);
        const std::size_t lin = row * static_cast<std::size_t>(size[0]) + i0;
        for (int q = 0; q < m; ++q) s[0][q] = static_cast<T>(lattice.first[0] + i0 + q);
        for (int a = 1; a < D; ++a)
          for (int q = 0; q < m; ++q) s[a][q] = static_cast<T>(lattice.first[a] + coord[a]);
        for (int a = 0; a < D; ++a)
          for (int q = 0; q < m; ++q) g[a][q] = s[a][q] + offset[a];
        displacement(g, m, u);
        if (trace == BackTrace::Euler) {
          std::copy(&u[0][0], &u[0][0] + D * kChunk, &uf[0][0]);
          std::copy(&u[0][0], &u[0][0] + D * kChunk, &ub[0][0]);
        } else {  // midpoint rule; the backward trace runs in -V, so its midpoint lies downstream
          for (int a = 0; a < D; ++a)
            for (int q = 0; q < m; ++q) p[a][q] = g[a][q] - T(0.5) * u[a][q];
          displacement(p, m, uf);
          for (int a = 0; a < D; ++a)
            for (int q = 0; q < m; ++q) p[a][q] = g[a][q] + T(0.5) * u[a][q];
          displacement(p, m, ub);
        }
        // Solid samples keep their own position as both feet: interpolation returns them unchanged.
        const std::uint8_t* sol = solid ? solid + lin : nullptr;
        for (int a = 0; a < D; ++a)
          for (int q = 0; q < m; ++q) p[a][q] = sol && sol[q] ? s[a][q] : s[a][q] - uf[a][q];
        locateChunk(lattice, p, m, st);
        storeFeet(lattice, st, m, forward, lin);
        if (touched)
          for (int q = 0; q < m; ++q) touched[lin + q] = !solid[lin + q] && readsSolid(st, q, solid);
        for (int a = 0; a < D; ++a)
          for (int q = 0; q < m; ++q) p[a][q] = sol && sol[q] ? s[a][q] : s[a][q] + ub[a][q];
        locateChunk(lattice, p, m, st);
        storeFeet(lattice, st, m, backward, lin);
        if (touched)
          for (int q = 0; q < m; ++q) touched[lin + q] |= !solid[lin + q] && readsSolid(st, q, solid);
      }
    }
  });
}

template <typename T, int D>
void sampleAtFeet(const SampleLattice<D>& lattice, const Feet<T, D>& feet, const T* src, T* dst, T* lo, T* hi) {
  tbb::parallel_for(tbb::blocked_range<std::size_t>(0, feet.base.size(), 4096),
                    [&](const tbb::blocked_range<std::size_t>& r) {
    ChunkStencil<T, D> st;
    for (std::size_t i = r.begin(); i < r.end(); i += kChunk) {
      const int m = static_cast<int>(std::min<std::size_t>(kChunk, r.end() - i));
      std::copy_n(feet.base.data() + i, m, st.base);
      const std::uint8_t* wrap = feet.wrap.data() + i;
      for (int a = 0; a < D; ++a) {
        std::copy_n(feet.t[a].data() + i, m, st.t[a]);
        const auto step = static_cast<std::int32_t>(lattice.step[a]), wrapStep = static_cast<std::int32_t>(lattice.wrapStep[a]);
        for (int q = 0; q < m; ++q) st.up[a][q] = (wrap[q] >> a) & 1 ? wrapStep : step;
      }
      interpolateChunk(st, src, m, T(1), dst + i, lo ? lo + i : nullptr, hi ? hi + i : nullptr);
    }
  });
}

#define MSIM_INSTANTIATE(T, D)                                                                                    \
  template void traceFeet<T, D>(const Grid<T, D>&, const AxisBoundaries<D>&, const MacGrid<D>&, double, BackTrace, \
                                const std::uint8_t*, Feet<T, D>&, Feet<T, D>&, std::uint8_t*,                     \
                                const BlockPlacement<D>&);                                                         \
  template void sampleAtFeet<T, D>(const SampleLattice<D>&, const Feet<T, D>&, const T*, T*, T*, T*);
MSIM_INSTANTIATE(float, 2)
MSIM_INSTANTIATE(float, 3)
MSIM_INSTANTIATE(double, 2)
MSIM_INSTANTIATE(double, 3)
#undef MSIM_INSTANTIATE

}  // namespace msim::numerics
