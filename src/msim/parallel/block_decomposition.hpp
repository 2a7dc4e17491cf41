#pragma once
// BlockDecomposition<D>: a uniform grid of res cells split into non-overlapping boxes of cells,
// one per process (Selle ch. 8.1: each rank updates only its own cells and receives what it reads
// from its neighbours). The boxes form a p_0 x ... x p_{D-1} lattice whose product is the rank
// count; the lattice is the one with the least interface area between blocks (the ghost traffic
// per step), among those leaving every block at least `minCells` cells along each axis.
// Ranks are numbered x fastest over the lattice, as the cells of a Grid are.
#include <string>

#include "msim/core/index_box.hpp"
#include "msim/core/vec.hpp"

namespace msim::parallel {

template <int D>
class BlockDecomposition {
 public:
  // The least-interface lattice for `ranks` processes. Throws InputError (naming `key`, the scene
  // key or option the rank count came from) when no lattice leaves minCells cells per block.
  BlockDecomposition(const IVec<D>& res, int ranks, int minCells, const std::string& key);
  // A given lattice (tests, and users who know their machine's topology).
  BlockDecomposition(const IVec<D>& res, const IVec<D>& blocks, int minCells, const std::string& key);

  const IVec<D>& res() const { return res_; }
  const IVec<D>& blocks() const { return blocks_; }
  int ranks() const { return blocks_.prod(); }
  IVec<D> blockCoord(int rank) const;
  // The rank of the block at lattice coordinate c, or -1 outside the lattice.
  int rankAt(const IVec<D>& c) const;
  // The cells rank r owns.
  IndexBox<D> ownedCells(int rank) const;
  // The rank that owns cell c (clamped into the grid).
  int ownerOfCell(const IVec<D>& c) const;

 private:
  IVec<D> res_;
  IVec<D> blocks_;
};

}  // namespace msim::parallel
