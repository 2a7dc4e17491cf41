#pragma once
// Collision response in Gauss-Seidel order on a mesh split among ranks (Selle ch. 8.2, Fig. 8.2).
// Every rank stores every node's velocity (the chapter's "every rank stores all particles"); a
// node belongs to one rank (recursiveMedianPartition). A collision item (a point-triangle or
// edge-edge pair: four nodes) is internal when one rank owns all its nodes, a boundary item
// otherwise. Phase I processes the connected components of the boundary items (items sharing a
// node), each on one rank, Gauss-Seidel within it; the components' nodes' new velocities go to
// every rank. Phase II processes each rank's internal items, Gauss-Seidel, on their owner; their
// nodes' velocities go to every rank. Components share no node with each other, nor do two ranks'
// internal items, so the result is bit for bit that of one serial Gauss-Seidel pass in the order
// serialOrder() (all components' items, then every rank's internal items). A Jacobi pass, every
// item from the same velocities, counts an impulse once per item that shares the node instead.
#include <mpi.h>

#include <array>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::parallel {

using CollisionItem = std::array<int, 4>;  // node indices; -1 for unused slots

struct TwoPhaseSchedule {
  std::vector<std::vector<int>> components;  // Phase I: items of each component, ascending
  std::vector<int> componentRank;            // the rank that processes each component
  std::vector<std::vector<int>> internal;    // Phase II: each rank's internal items, ascending
  // The serial order the two phases reproduce.
  std::vector<int> serialOrder() const;
};

// The schedule for `items` with node owners `owner` among `ranks` ranks. A component is processed
// by the lowest rank owning one of its nodes (the chapter's rule for a pair's owner).
TwoPhaseSchedule twoPhaseSchedule(const std::vector<CollisionItem>& items, const std::vector<int>& owner, int ranks);

// The nodes of `items` listed in `which`, each once, ascending.
std::vector<int> nodesOf(const std::vector<CollisionItem>& items, const std::vector<int>& which);

// Every rank's velocities of `nodes` (its own list) made known to every rank. Collective.
void shareVelocities(const std::vector<int>& nodes, std::vector<Vec3>& v, MPI_Comm comm);

// The two phases; respond(item index, v) applies one item's impulse to v. Collective; every rank
// passes the same schedule and velocities and ends with the same velocities.
template <typename Respond>
void respondTwoPhase(const TwoPhaseSchedule& s, const std::vector<CollisionItem>& items, std::vector<Vec3>& v,
                     int rank, MPI_Comm comm, Respond&& respond) {
  std::vector<int> mine;
  for (std::size_t c = 0; c < s.components.size(); ++c)
    if (s.componentRank[c] == rank)
      for (int item : s.components[c]) {
        respond(item, v);
        mine.push_back(item);
      }
  shareVelocities(nodesOf(items, mine), v, comm);
  for (int item : s.internal[static_cast<std::size_t>(rank)]) respond(item, v);
  shareVelocities(nodesOf(items, s.internal[static_cast<std::size_t>(rank)]), v, comm);
}

}  // namespace msim::parallel
