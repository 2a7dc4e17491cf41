#pragma once
// GridBlock<D>: one rank's part of a split grid. The rank owns the cells `owned` of the global
// grid and stores them with up to `ghost` layers of cells around them, clipped to the domain, so
// its fields are ordinary Grids over localSpec() (cell c of the local grid is global cell
// c + cellOrigin()). Clipping makes a block's border on a domain side the domain's border: a
// solver's own treatment of the grid's edges (clamping, wall faces, inflow cells) then acts
// there exactly as in the serial run, and at the edges between blocks it only touches the
// outermost ghost layers, which the next exchange refills.
//
// A field's samples are cell centres or, along the axes where it has one sample more than cells
// (`extra` = 1), faces. A rank owns the samples of its cells and, on a face axis, the face on its
// upper side only where that side is the domain's: each face has one owner.
#include "msim/core/block_placement.hpp"
#include "msim/core/grid_spec.hpp"
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
  // The cells rank r stores: its own and the ghost layers inside the domain.
  IndexBox<D> storedCells(int r) const {
    IndexBox<D> box = decomposition.ownedCells(r);
    box.lo = (box.lo - IVec<D>::Constant(ghost)).cwiseMax(0);
    box.hi = (box.hi + IVec<D>::Constant(ghost)).cwiseMin(global.res);
    return box;
  }
  IVec<D> cellOrigin() const { return storedCells(rank).lo; }
  GridSpec<D> localSpec() const {
    const IndexBox<D> s = storedCells(rank);
    return GridSpec<D>(global.origin + s.lo.template cast<double>() * global.dx, global.dx, s.size());
  }
  BlockPlacement<D> placement() const { return {cellOrigin(), global.res}; }
  // The owned cells in local coordinates.
  IndexBox<D> ownedLocal() const {
    const IndexBox<D> o = owned();
    return {o.lo - cellOrigin(), o.hi - cellOrigin()};
  }

  // Samples (global indices) that rank r owns / stores, of a field with `extra` samples more
  // than cells per axis.
  IndexBox<D> ownedSamples(int r, const IVec<D>& extra) const {
    IndexBox<D> box = decomposition.ownedCells(r);
    for (int a = 0; a < D; ++a)
      if (box.hi[a] == global.res[a]) box.hi[a] += extra[a];
    return box;
  }
  IndexBox<D> storedSamples(int r, const IVec<D>& extra) const {
    IndexBox<D> box = storedCells(r);
    box.hi += extra;
    return box;
  }
};

}  // namespace msim::parallel
