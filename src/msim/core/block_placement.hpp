#pragma once
// Where a grid lies inside a larger one that is split among processes (msim/parallel): its cell 0
// is the global grid's cell `cellOrigin`, and the global grid has `globalRes` cells. Schemes that
// clamp or trace positions then work in global sample coordinates, clamping at the global
// domain's border only, so a block with wide enough ghost layers computes its samples bit for bit
// as the whole grid would. The default, a grid that is the whole domain, is every serial run.
#include <cstddef>
#include <cstdint>

#include "msim/core/vec.hpp"

namespace msim {

template <int D>
struct BlockPlacement {
  IVec<D> cellOrigin = IVec<D>::Zero();
  IVec<D> globalRes = IVec<D>::Zero();  // zero: the grid is the whole domain
  bool whole() const { return globalRes.isZero(); }
  // The global grid's linear index (x fastest, as Grid's) of the block's cell c (`local`: c's index
  // in the block): a per-cell random stream that a split run draws as the whole grid does.
  std::uint64_t globalIndex(const IVec<D>& c, std::size_t local) const {
    if (whole()) return local;
    std::uint64_t index = 0;
    for (int a = D - 1; a >= 0; --a)
      index = index * static_cast<std::uint64_t>(globalRes[a]) + static_cast<std::uint64_t>(c[a] + cellOrigin[a]);
    return index;
  }
};

}  // namespace msim
