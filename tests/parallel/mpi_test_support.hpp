#pragma once
// What the MPI tests share: the world communicator's size and rank, and a check every rank
// agrees on (rank 0 compares the gathered field; the verdict is broadcast so that every rank
// fails or passes together and no rank leaves a collective call early).
#include <mpi.h>

#include <optional>
#include <type_traits>
#include <utility>
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

// What a split run is measured against, on rank 0 (empty elsewhere): the same run on rank 0 alone
// and the serial solver's run.
template <typename Run>
struct References {
  std::optional<Run> one, serial;
};

// oneRank(comm) on rank 0 with a communicator of its own and, at the same time, serial() on the
// last rank (the two references take two cores instead of one after the other); toRoot(run, from),
// called on rank 0 (whose run starts as `blank`) and on `from`, moves the serial run to rank 0.
template <typename Run, typename OneRank, typename Serial, typename ToRoot>
References<Run> referenceRuns(OneRank&& oneRank, Serial&& serial, Run blank, ToRoot&& toRoot) {
  References<Run> r;
  MPI_Comm alone;
  MPI_Comm_split(MPI_COMM_WORLD, worldRank() == 0 ? 0 : MPI_UNDEFINED, 0, &alone);
  if (worldRank() == 0) {
    r.one = oneRank(alone);
    MPI_Comm_free(&alone);
  }
  const int from = worldSize() - 1;
  if (worldRank() == from) r.serial = serial();
  else if (worldRank() == 0) r.serial = std::move(blank);
  if (r.serial) toRoot(*r.serial, from);
  if (worldRank() != 0) r.serial.reset();
  return r;
}

}  // namespace msim::parallel::testing
