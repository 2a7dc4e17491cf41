#pragma once
// Point sampling of gridded fields at world positions, for any sample offset (cell-centred grids
// and MAC face grids alike). Outside the sampled range the position is clamped onto it, which is
// the zero-gradient extension of the border samples.
//
// sampleLinear: D-linear interpolation of the 2^D surrounding samples.
// sampleMonotoneCubic: tensor-product cubic Hermite, one 1D pass per axis (x first). Node slopes
// are the centred differences limited Fritsch-Carlson style: zero at a local extremum, and at most
// three times either adjacent secant, which keeps every 1D pass inside the range of its interval
// ends. The result therefore never leaves the range of the 2^D surrounding samples (no new
// extrema, no overshoot at steps). At a grid-edge node the slope is the one-sided three-point
// estimate, limited the same way (as in PCHIP), so linear data is reproduced exactly up to the
// grid edge and the border intervals keep the accuracy of the interior.
//
// Weights are computed in double; nothing allocates, so both are safe in per-particle loops.
#include <algorithm>
#include <cmath>
#include <cstddef>
#include <type_traits>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim {

namespace interpolation_detail {

// Sample coordinate s clamped to [0, n-1]; a NaN lands on 0 so a bad position can never index
// outside the grid.
inline double clampToSamples(double s, int n) {
  const double hi = static_cast<double>(n - 1);
  return s > 0.0 ? (s < hi ? s : hi) : 0.0;
}

struct LinearAxis {
  std::ptrdiff_t lo, hi;  // memory offsets of the two bracketing samples
  double t;               // fraction of the way from lo to hi
};

inline LinearAxis linearAxis(double s, int n, std::ptrdiff_t stride) {
  if (n < 2) return {0, 0, 0.0};
  s = clampToSamples(s, n);
  const int i0 = std::min(static_cast<int>(s), n - 2);
  return {i0 * stride, (i0 + 1) * stride, s - i0};
}

template <int Axis>
double linearPass(const float* p, const LinearAxis* axes) {
  if constexpr (Axis < 0) {
    return *p;
  } else {
    const LinearAxis& a = axes[Axis];
    const double lo = linearPass<Axis - 1>(p + a.lo, axes);
    const double hi = linearPass<Axis - 1>(p + a.hi, axes);
    return lo + a.t * (hi - lo);
  }
}

struct CubicAxis {
  std::ptrdiff_t offset[4];  // samples i0-1 .. i0+2, clamped into the grid
  double t;                  // position inside [i0, i0+1]
  bool hasLeft, hasRight;    // whether i0-1 and i0+2 are real samples
};

inline CubicAxis cubicAxis(double s, int n, std::ptrdiff_t stride) {
  if (n < 2) return {{0, 0, 0, 0}, 0.0, false, false};
  s = clampToSamples(s, n);
  const int i0 = std::min(static_cast<int>(s), n - 2);
  return {{std::max(i0 - 1, 0) * stride, i0 * stride, (i0 + 1) * stride, std::min(i0 + 2, n - 1) * stride},
          s - i0,
          i0 >= 1,
          i0 + 2 <= n - 1};
}

// Node slope from its two adjacent secants: zero at an extremum, otherwise the centred difference
// capped at 3x the smaller secant (inside the Fritsch-Carlson monotonicity region).
inline double limitedSlope(double left, double right) {
  if (left * right <= 0.0) return 0.0;
  const double bound = 3.0 * std::min(std::abs(left), std::abs(right));
  const double centred = 0.5 * (left + right);
  return std::copysign(std::min(std::abs(centred), bound), centred);
}

// Slope at a grid-edge node from the secant of its interval (`near`) and the next one (`far`):
// the three-point one-sided difference, zeroed if it points against `near`, capped at 3x `near`.
inline double edgeSlope(double near, double far) {
  const double m = 0.5 * (3.0 * near - far);
  if (m * near <= 0.0) return 0.0;
  return std::abs(m) > 3.0 * std::abs(near) ? 3.0 * near : m;
}

inline double monotoneHermite(const double f[4], const CubicAxis& a) {
  const double secant = f[2] - f[1];
  const double left = f[1] - f[0], right = f[3] - f[2];  // meaningful only where the neighbour exists
  const double m1 = a.hasLeft ? limitedSlope(left, secant) : (a.hasRight ? edgeSlope(secant, right) : secant);
  const double m2 = a.hasRight ? limitedSlope(secant, right) : (a.hasLeft ? edgeSlope(secant, left) : secant);
  const double t = a.t, t2 = t * t, t3 = t2 * t;
  return (2.0 * t3 - 3.0 * t2 + 1.0) * f[1] + (t3 - 2.0 * t2 + t) * m1 + (3.0 * t2 - 2.0 * t3) * f[2] + (t3 - t2) * m2;
}

template <int Axis>
double cubicPass(const float* p, const CubicAxis* axes) {
  if constexpr (Axis < 0) {
    return *p;
  } else {
    const CubicAxis& a = axes[Axis];
    const double f[4] = {cubicPass<Axis - 1>(p + a.offset[0], axes), cubicPass<Axis - 1>(p + a.offset[1], axes),
                         cubicPass<Axis - 1>(p + a.offset[2], axes), cubicPass<Axis - 1>(p + a.offset[3], axes)};
    return monotoneHermite(f, a);
  }
}

}  // namespace interpolation_detail

// The position parameter is non-deduced so Eigen expressions (e.g. p.cast<double>()) convert.
template <int D>
float sampleLinear(const Grid<float, D>& grid, const std::type_identity_t<Vec<D>>& worldPos) {
  using namespace interpolation_detail;
  const Vec<D> s = grid.toSampleSpace(worldPos);
  LinearAxis axes[D];
  for (int a = 0; a < D; ++a) axes[a] = linearAxis(s[a], grid.size()[a], grid.stride(a));
  return static_cast<float>(linearPass<D - 1>(grid.data().data(), axes));
}

template <int D>
float sampleMonotoneCubic(const Grid<float, D>& grid, const std::type_identity_t<Vec<D>>& worldPos) {
  using namespace interpolation_detail;
  const Vec<D> s = grid.toSampleSpace(worldPos);
  CubicAxis axes[D];
  for (int a = 0; a < D; ++a) axes[a] = cubicAxis(s[a], grid.size()[a], grid.stride(a));
  return static_cast<float>(cubicPass<D - 1>(grid.data().data(), axes));
}

// Velocity at a world position: each component interpolated on its own face grid.
template <int D>
Vec<D> sampleLinear(const MacGrid<D>& velocity, const std::type_identity_t<Vec<D>>& worldPos) {
  Vec<D> u;
  for (int a = 0; a < D; ++a) u[a] = sampleLinear<D>(velocity.component(a), worldPos);
  return u;
}

}  // namespace msim
