#pragma once
// Vector kernels of the pressure solvers. Values are stored in float; dot products accumulate in
// double through parallelSum's fixed blocks, so a solve gives the same iterates whatever the
// thread count.
#include <algorithm>
#include <cmath>
#include <vector>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

inline double dot(const std::vector<float>& a, const std::vector<float>& b) {
  return parallelSum(a.size(), [&](std::size_t i) { return double(a[i]) * double(b[i]); });
}

inline double maxAbs(const std::vector<float>& a) {
  return parallelMax(a.size(), [&](std::size_t i) { return std::abs(a[i]); });
}

}  // namespace msim::numerics
