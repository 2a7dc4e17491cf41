#pragma once
// Vector kernels of the pressure solvers. Values are stored in float; dot products accumulate in
// double through parallelSum's fixed blocks, so a solve gives the same iterates whatever the
// thread count.
#include <algorithm>
#include <cmath>
#include <vector>

#include <tbb/blocked_range.h>
#include <tbb/parallel_reduce.h>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

inline double dot(const std::vector<float>& a, const std::vector<float>& b) {
  return parallelSum(a.size(), [&](std::size_t i) { return double(a[i]) * double(b[i]); });
}

// Max-norm; max is order independent, so the plain parallel reduction is deterministic.
inline double maxAbs(const std::vector<float>& a) {
  return tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, a.size(), 4096), 0.0f,
      [&](const tbb::blocked_range<std::size_t>& r, float m) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) m = std::max(m, std::abs(a[i]));
        return m;
      },
      [](float x, float y) { return std::max(x, y); });
}

}  // namespace msim::numerics
