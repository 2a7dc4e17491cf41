#include "msim/rigid/broad_phase.hpp"

#include <algorithm>
#include <cmath>
#include <cstdint>

namespace msim::rigid {
namespace {

// 21 bits per axis, offset so negative cells pack too; ample for simulation domains.
constexpr std::int64_t kOffset = 1 << 20;
std::uint64_t packCell(std::int64_t i, std::int64_t j, std::int64_t k) {
  return (static_cast<std::uint64_t>(i + kOffset) << 42) |
         (static_cast<std::uint64_t>(j + kOffset) << 21) | static_cast<std::uint64_t>(k + kOffset);
}

}  // namespace

std::vector<std::pair<int, int>> overlappingPairs(const std::vector<Vec3>& centres,
                                                  const std::vector<double>& radii,
                                                  const std::vector<char>& skip, double margin) {
  const int n = static_cast<int>(centres.size());
  std::vector<std::pair<int, int>> pairs;
  if (n < 2) return pairs;
  double maxRadius = 0.0;
  for (double r : radii) maxRadius = std::max(maxRadius, r + margin);
  const double cell = std::max(2.0 * maxRadius, 1e-12);
  std::vector<IVec3> cells(n);
  std::vector<std::pair<std::uint64_t, int>> sorted(n);
  for (int i = 0; i < n; ++i) {
    for (int k = 0; k < 3; ++k) cells[i][k] = static_cast<int>(std::floor(centres[i][k] / cell));
    sorted[i] = {packCell(cells[i].x(), cells[i].y(), cells[i].z()), i};
  }
  std::sort(sorted.begin(), sorted.end());
  for (int i = 0; i < n; ++i) {
    for (int dx = -1; dx <= 1; ++dx)
      for (int dy = -1; dy <= 1; ++dy)
        for (int dz = -1; dz <= 1; ++dz) {
          const std::uint64_t key =
              packCell(cells[i].x() + dx, cells[i].y() + dy, cells[i].z() + dz);
          auto it = std::lower_bound(sorted.begin(), sorted.end(), std::make_pair(key, 0));
          for (; it != sorted.end() && it->first == key; ++it) {
            const int j = it->second;
            if (j <= i || (skip[i] && skip[j])) continue;
            const double reach = radii[i] + radii[j] + 2.0 * margin;
            if ((centres[i] - centres[j]).squaredNorm() <= reach * reach) pairs.emplace_back(i, j);
          }
        }
  }
  std::sort(pairs.begin(), pairs.end());
  return pairs;
}

}  // namespace msim::rigid
