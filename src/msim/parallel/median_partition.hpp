#pragma once
// The recursive median split of Selle ch. 8.2: a mesh's nodes are cut into 2^k parts of equal
// count (within one) by splitting the node set at the median of its longest extent, then each half
// again. Each part is one rank's: it computes the forces of its nodes and owns their rows of the
// implicit solve; the partition is fixed for the run (the chapter does not repartition as cloth
// folds, and names the cost).
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::parallel {

// owner[i] in [0, parts) for every position; `parts` must be a power of two (std::invalid_argument
// otherwise). Deterministic: ties in position are broken by index.
std::vector<int> recursiveMedianPartition(const std::vector<Vec3>& positions, int parts);

}  // namespace msim::parallel
