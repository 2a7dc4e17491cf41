#pragma once
// What the MPI tests share: the world communicator's size and rank, and a check every rank
// agrees on (rank 0 compares the gathered field; the verdict is broadcast so that every rank
// fails or passes together and no rank leaves a collective call early).
#include <mpi.h>

namespace msim::parallel::testing {

inline int worldSize() {
  int n = 1;
  MPI_Comm_size(MPI_COMM_WORLD, &n);
  return n;
}

inline int worldRank() {
  int r = 0;
  MPI_Comm_rank(MPI_COMM_WORLD, &r);
  return r;
}

// Rank 0's value of `flag` on every rank.
inline bool fromRoot(bool flag) {
  int v = flag;
  MPI_Bcast(&v, 1, MPI_INT, 0, MPI_COMM_WORLD);
  return v != 0;
}

}  // namespace msim::parallel::testing
