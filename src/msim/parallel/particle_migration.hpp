#pragma once
// Particle migration (Selle ch. 8.1): every marker particle has one owner, the rank whose cells
// hold its position; after the particles moved (with the ghosted velocity), those that left a
// rank's cells go to their new owner with every attribute channel. Positions outside the domain
// belong to the owner of the nearest cell.
#include <mpi.h>

#include <cstddef>
#include <vector>

#include "msim/core/particles.hpp"
#include "msim/parallel/grid_block.hpp"

namespace msim::parallel {

// Sends the particles this rank no longer owns to their owners and appends those it receives.
// Every rank's particles must have the same channels. Collective; returns the count sent.
template <int D>
std::size_t migrateParticles(Particles<D>& particles, const GridBlock<D>& block, MPI_Comm comm);

// The rank that owns a particle at `position`.
template <int D>
int ownerOf(const Vec<D>& position, const GridBlock<D>& block);
template <int D>
int ownerOf(const Vecf<D>& position, const GridBlock<D>& block) {
  return ownerOf<D>(Vec<D>(position.template cast<double>()), block);
}

// Particles kept as rows of `width` doubles whose first D entries are the position [m] (solvers
// whose particles carry double positions, such as the particle level set's markers).
// migrateRows: as migrateParticles, on rows (kept rows in order, received ones appended).
// Collective; returns the count sent.
template <int D>
std::size_t migrateRows(std::vector<double>& rows, int width, const GridBlock<D>& block, MPI_Comm comm);
// Copies of the other ranks' rows whose positions lie in cells within `reach` cells of this rank's
// own (at most the ghost layers): the neighbours' particles whose stencils touch an owned cell.
// Each rank passes its own rows. Collective.
template <int D>
std::vector<double> neighbourRows(const std::vector<double>& rows, int width, int reach, const GridBlock<D>& block,
                                  MPI_Comm comm);
// Every rank's rows on rank 0, in rank order (other ranks: empty). Collective.
std::vector<double> gatherRowsToRoot(const std::vector<double>& rows, MPI_Comm comm);

}  // namespace msim::parallel
