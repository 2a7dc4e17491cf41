#pragma once
// Multilinear interpolation as per-axis taps: each axis contributes its two neighbouring samples
// (as offsets into the data, stride included) and the weight of the upper one, and the value is
// the weighted sum over the 2^N corners. Grid resampling (core/resample.hpp), the turbulent
// wind's lattice and the noise tile (turbulence/) build their taps differently (clamped,
// periodic, tabulated per axis) and share the blend.
#include <algorithm>
#include <array>
#include <cmath>
#include <cstddef>
#include <cstdint>

namespace msim {

struct LinearTap {
  std::size_t lower = 0, upper = 0;  // offsets of the two samples along the axis (stride included)
  float fraction = 0.0f;             // weight of the upper sample
};

// The tap at sample coordinate g on a periodic axis of n samples: indices wrapped into [0, n).
inline LinearTap periodicTap(double g, int n, std::size_t stride) {
  const double floor = std::floor(g);
  const auto k = static_cast<std::int64_t>(floor);
  // A power-of-two count wraps with a mask (two's complement), others with a modulo.
  const std::int64_t i = (n & (n - 1)) == 0 ? (k & (n - 1)) : ((k % n) + n) % n;
  const std::int64_t j = (i + 1 == n) ? 0 : i + 1;
  return LinearTap{static_cast<std::size_t>(i) * stride, static_cast<std::size_t>(j) * stride,
                   static_cast<float>(g - floor)};
}

// The tap at sample coordinate s on an axis of n samples, clamped to its ends (as sampleLinear).
inline LinearTap clampedTap(double s, int n, std::size_t stride) {
  const double c = s < 0.0 ? 0.0 : (s > n - 1 ? double(n - 1) : s);
  const int lo = n > 1 ? std::min(static_cast<int>(c), n - 2) : 0;
  const int hi = n > 1 ? lo + 1 : 0;
  return LinearTap{static_cast<std::size_t>(lo) * stride, static_cast<std::size_t>(hi) * stride,
                   static_cast<float>(c - lo)};
}

namespace detail {
// Axes 0 .. A blended below the sample at offset `base`: a tree of lerps (the 2^N corners read
// once each, independent chains instead of one running sum).
template <int A, int N, typename T>
[[gnu::always_inline]] inline T blendBelow(const std::array<LinearTap, N>& taps, const T* data, std::size_t base) {
  if constexpr (A < 0) {
    return data[base];
  } else {
    const T lower = blendBelow<A - 1, N>(taps, data, base + taps[A].lower);
    const T upper = blendBelow<A - 1, N>(taps, data, base + taps[A].upper);
    return lower + taps[A].fraction * (upper - lower);
  }
}
}  // namespace detail

// sum over the corners of prod_axes (fraction or 1 - fraction) * data[sum of offsets], evaluated as
// nested lerps, axis 0 innermost.
template <int N, typename T>
[[gnu::always_inline]] inline T blendCorners(const std::array<LinearTap, N>& taps, const T* data) {
  return detail::blendBelow<N - 1, N>(taps, data, 0);
}

}  // namespace msim
