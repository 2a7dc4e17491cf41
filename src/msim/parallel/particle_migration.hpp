#pragma once
// Particle migration (Selle ch. 8.1): every marker particle has one owner, the rank whose cells
// hold its position; after the particles moved (with the ghosted velocity), those that left a
// rank's cells go to their new owner with every attribute channel. Positions outside the domain
// belong to the owner of the nearest cell.
#include <mpi.h>

#include <cstddef>

#include "msim/core/particles.hpp"
#include "msim/parallel/grid_block.hpp"

namespace msim::parallel {

// Sends the particles this rank no longer owns to their owners and appends those it receives.
// Every rank's particles must have the same channels. Collective; returns the count sent.
template <int D>
std::size_t migrateParticles(Particles<D>& particles, const GridBlock<D>& block, MPI_Comm comm);

// The rank that owns a particle at `position`.
template <int D>
int ownerOf(const Vecf<D>& position, const GridBlock<D>& block);

}  // namespace msim::parallel
