#pragma once
// What the MPI tests share: the world communicator's size and rank, and a check every rank
// agrees on (rank 0 compares the gathered field; the verdict is broadcast so that every rank
// fails or passes together and no rank leaves a collective call early).
#include <mpi.h>

#include <type_traits>
#include <vector>

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

// The rank that runs the serial solver's reference beside rank 0's one-rank run (both alone, at
// once: the tests' reference runs take two cores instead of one after the other); rank 0 itself
// when there is no other.
inline int serialReferenceRank() { return worldSize() - 1; }

// Rank `from`'s `values` into rank 0's, which holds as many. Only ranks 0 and `from` call it.
template <typename T>
void sendToRoot(std::vector<T>& values, int from) {
  static_assert(std::is_same_v<T, float> || std::is_same_v<T, double>);
  const MPI_Datatype type = std::is_same_v<T, float> ? MPI_FLOAT : MPI_DOUBLE;
  if (from == 0) return;
  if (worldRank() == from)
    MPI_Send(values.data(), static_cast<int>(values.size()), type, 0, 0, MPI_COMM_WORLD);
  else
    MPI_Recv(values.data(), static_cast<int>(values.size()), type, from, 0, MPI_COMM_WORLD, MPI_STATUS_IGNORE);
}

}  // namespace msim::parallel::testing
