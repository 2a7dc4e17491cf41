#include "msim/parallel/median_partition.hpp"

#include <algorithm>
#include <limits>
#include <numeric>
#include <stdexcept>

namespace msim::parallel {

namespace {

// Splits nodes[begin, end) into `parts` parts numbered from firstPart.
void split(const std::vector<Vec3>& x, std::vector<int>& nodes, std::size_t begin, std::size_t end, int firstPart,
           int parts, std::vector<int>& owner) {
  if (parts == 1) {
    for (std::size_t k = begin; k < end; ++k) owner[static_cast<std::size_t>(nodes[k])] = firstPart;
    return;
  }
  Vec3 lo = Vec3::Constant(std::numeric_limits<double>::infinity()), hi = -lo;
  for (std::size_t k = begin; k < end; ++k) {
    lo = lo.cwiseMin(x[static_cast<std::size_t>(nodes[k])]);
    hi = hi.cwiseMax(x[static_cast<std::size_t>(nodes[k])]);
  }
  int axis = 0;
  (hi - lo).maxCoeff(&axis);
  const std::size_t middle = begin + (end - begin) / 2;
  std::nth_element(nodes.begin() + static_cast<std::ptrdiff_t>(begin), nodes.begin() + static_cast<std::ptrdiff_t>(middle),
                   nodes.begin() + static_cast<std::ptrdiff_t>(end), [&](int a, int b) {
                     const double xa = x[static_cast<std::size_t>(a)][axis], xb = x[static_cast<std::size_t>(b)][axis];
                     return xa < xb || (xa == xb && a < b);
                   });
  split(x, nodes, begin, middle, firstPart, parts / 2, owner);
  split(x, nodes, middle, end, firstPart + parts / 2, parts / 2, owner);
}

}  // namespace

std::vector<int> recursiveMedianPartition(const std::vector<Vec3>& positions, int parts) {
  if (parts < 1 || (parts & (parts - 1)) != 0)
    throw std::invalid_argument("recursive median partition: the part count must be a power of two");
  std::vector<int> nodes(positions.size()), owner(positions.size(), 0);
  std::iota(nodes.begin(), nodes.end(), 0);
  split(positions, nodes, 0, nodes.size(), 0, parts, owner);
  return owner;
}

}  // namespace msim::parallel
