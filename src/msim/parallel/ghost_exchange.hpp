#pragma once
// Ghost exchange (Selle ch. 8.1): each rank receives, from every rank that owns them, the samples
// its ghost layers hold, for one sample layout (cell centres or one face component). The peers
// and boxes are worked out once per layout: a rank receives the intersection of a peer's owned
// samples with its own stored ones, and sends the intersection of its owned samples with the
// peer's stored ones, so corner and edge neighbours come without special cases (26 in 3D, more
// when the ghost layers are wider than a neighbour's block).
//
// gatherToRoot puts a split field back together on rank 0 (output, and tests against serial runs).
#include <mpi.h>

#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/parallel/grid_block.hpp"

namespace msim::parallel {

// Samples per axis beyond the cell count of grid g: 1 on a face grid's own axis, else 0.
template <typename T, int D>
IVec<D> extraSamples(const Grid<T, D>& g) {
  return g.size() - g.spec().res;
}

template <typename T, int D>
class GhostExchange {
 public:
  GhostExchange(const GridBlock<D>& block, const IVec<D>& extra, MPI_Comm comm);
  // Fills the ghost samples of `local` (a field over block.localSpec() with this layout) from
  // their owners. Collective: every rank of comm calls it for the same field.
  void exchange(Grid<T, D>& local);
  // Samples one exchange brings into this rank's ghost layers (the communication volume).
  std::size_t receivedSamples() const;

 private:
  struct Peer {
    int rank;
    IndexBox<D> send, receive;  // global sample indices
    std::vector<T> sendBuffer, receiveBuffer;
  };
  IVec<D> origin_;  // global index of local sample 0
  MPI_Comm comm_;
  std::vector<Peer> peers_;
  std::vector<MPI_Request> requests_;
};

// The ghost exchanges of every component of a MAC grid.
template <int D>
class MacGhostExchange {
 public:
  MacGhostExchange(const GridBlock<D>& block, MPI_Comm comm);
  void exchange(MacGrid<D>& local);
  // One component alone (a local grid of that face layout).
  void exchange(Grid<float, D>& component, int axis) { components_[static_cast<std::size_t>(axis)].exchange(component); }
  std::size_t receivedSamples() const;

 private:
  std::vector<GhostExchange<float, D>> components_;
};

// Copies the samples of `box` (global indices) between a local grid whose sample 0 is global
// sample `origin` and a contiguous buffer (x fastest).
template <typename T, int D>
void packBox(const Grid<T, D>& local, const IVec<D>& origin, const IndexBox<D>& box, T* out);
template <typename T, int D>
void unpackBox(Grid<T, D>& local, const IVec<D>& origin, const IndexBox<D>& box, const T* in);

// The owned samples of every rank's `local` gathered into one global field on rank 0 (over
// block.global, with the local field's layout); other ranks get an empty grid. Collective.
template <typename T, int D>
Grid<T, D> gatherToRoot(const Grid<T, D>& local, const GridBlock<D>& block, MPI_Comm comm);
template <int D>
MacGrid<D> gatherToRoot(const MacGrid<D>& local, const GridBlock<D>& block, MPI_Comm comm);

// The block's local part of a global field every rank holds (initial conditions given as whole
// fields).
template <typename T, int D>
Grid<T, D> localPart(const Grid<T, D>& global, const GridBlock<D>& block);
template <int D>
MacGrid<D> localPart(const MacGrid<D>& global, const GridBlock<D>& block);

}  // namespace msim::parallel
