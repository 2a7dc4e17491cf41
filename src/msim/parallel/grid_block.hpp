#pragma once
// GridBlock<D>: one rank's part of a split grid. The rank owns the cells `owned` of the global
// grid and stores them with `ghost` layers of cells around them on every side, so its fields are
// ordinary Grids over localSpec() (cell c of the local grid is global cell c + cellOrigin()).
// Ghost layers outside the global domain are stored too (uniform local layout) and never read:
// the schemes clamp at the global border (BlockPlacement).
//
// A field's samples are cell centres or, along the axes where it has one sample more than cells
// (`extra` = 1), faces. A rank owns the samples of its cells and, on a face axis, the face on its
// upper side only where that side is the domain's: each face has one owner.
#include "msim/core/grid_spec.hpp"
#include "msim/numerics/advection/field_layout.hpp"
#include "msim/parallel/block_decomposition.hpp"

namespace msim::parallel {

template <int D>
struct GridBlock {
  GridSpec<D> global;
  BlockDecomposition<D> decomposition;
  int rank = 0;
  int ghost = 0;

  GridBlock(const GridSpec<D>& global_, const BlockDecomposition<D>& decomposition_, int rank_, int ghost_)
      : global(global_), decomposition(decomposition_), rank(rank_), ghost(ghost_) {}

  IndexBox<D> owned() const { return decomposition.ownedCells(rank); }
  IVec<D> cellOrigin() const { return owned().lo - IVec<D>::Constant(ghost); }
  GridSpec<D> localSpec() const {
    const IndexBox<D> o = owned();
    return GridSpec<D>(global.origin + cellOrigin().template cast<double>() * global.dx, global.dx,
                       o.size() + IVec<D>::Constant(2 * ghost));
  }
  numerics::BlockPlacement<D> placement() const { return {cellOrigin(), global.res}; }

  // Samples (global indices) that rank r owns / stores, of a field with `extra` samples more
  // than cells per axis.
  IndexBox<D> ownedSamples(int r, const IVec<D>& extra) const {
    IndexBox<D> box = decomposition.ownedCells(r);
    for (int a = 0; a < D; ++a)
      if (box.hi[a] == global.res[a]) box.hi[a] += extra[a];
    return box;
  }
  IndexBox<D> storedSamples(int r, const IVec<D>& extra) const {
    IndexBox<D> box = decomposition.ownedCells(r);
    box.lo -= IVec<D>::Constant(ghost);
    box.hi += IVec<D>::Constant(ghost) + extra;
    return box;
  }
};

}  // namespace msim::parallel
