#pragma once
// Broad phase: candidate body pairs whose bounding spheres overlap, from a uniform grid with the
// cell size of the largest bounding diameter (so only the 27 neighbouring cells can overlap).
// Cells are found by sorting (cell key, body index), so the result does not depend on hashing or
// thread timing: pairs come out sorted by (i, j), i < j, and contact order is deterministic.
#include <utility>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::rigid {

// centres[i] and radii[i] bound body i; pairs with skip[i] && skip[j] (two static bodies) are
// left out. `margin` widens every bound.
std::vector<std::pair<int, int>> overlappingPairs(const std::vector<Vec3>& centres,
                                                  const std::vector<double>& radii,
                                                  const std::vector<char>& skip, double margin);

}  // namespace msim::rigid
