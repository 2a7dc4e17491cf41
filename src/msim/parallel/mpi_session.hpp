#pragma once
// The MPI environment of a run split over processes: MPI_Init on construction, MPI_Finalize on
// destruction, and the rules every rank follows (Selle ch. 8: ranks receive what they read, so
// all writes are local). Input errors are found identically on every rank, so every rank exits
// with code 2 and only rank 0 prints; an error on some ranks only ends the whole job through
// MPI_Abort, so no rank waits forever for a message that will not come.
#include <mpi.h>

#include <exception>
#include <stdexcept>
#include <string>
#include <type_traits>
#include <vector>

namespace msim::parallel {

class MpiSession {
 public:
  MpiSession(int& argc, char**& argv);
  ~MpiSession();
  MpiSession(const MpiSession&) = delete;
  MpiSession& operator=(const MpiSession&) = delete;
};

// Whether this process was started by mpirun (or another MPI launcher: Slurm's srun, Hydra),
// read from the environment the launchers set. `msim run` initialises MPI only then, so a plain
// run behaves as if MPI were not there.
bool launchedByMpi();
// MPI_COMM_WORLD's rank and size once MPI runs; 0 and 1 otherwise.
int worldRank();
int worldSize();
// Ranks of MPI_COMM_WORLD on this machine (1 without MPI). Collective.
int ranksOnThisNode();
// Whether `flag` holds on some rank (the flag itself without MPI). Collective.
bool anyRank(bool flag);
// Rank 0's `value` on every rank (the value itself without MPI). Collective.
long fromRankZero(long value);

// Agrees on an error that may have struck some ranks only (a scene's shape that lies outside
// one rank's block): `local` is this rank's exception or null. If any rank failed, every rank
// throws the error of the lowest failing rank (InputError, SimulationError, or else
// std::runtime_error, with its message), so that all stop together and rank 0 can report it;
// otherwise it returns. Collective; without MPI it rethrows `local` if set.
void agreeOnFailure(std::exception_ptr local, MPI_Comm comm);

// Runs f on every rank of MPI_COMM_WORLD with agreeOnFailure around it.
template <typename F>
auto collectively(F&& f) -> decltype(f()) {
  std::exception_ptr failure;
  try {
    if constexpr (std::is_void_v<decltype(f())>) {
      f();
      agreeOnFailure(nullptr, MPI_COMM_WORLD);
      return;
    } else {
      auto result = f();
      agreeOnFailure(nullptr, MPI_COMM_WORLD);
      return result;
    }
  } catch (...) {
    failure = std::current_exception();
  }
  agreeOnFailure(failure, MPI_COMM_WORLD);
  throw std::logic_error("agreeOnFailure returned after a failure");  // not reached
}

// Every rank's `mine`, joined in rank order, on every rank of `comm`. Collective.
std::vector<double> joinedFromAll(const std::vector<double>& mine, MPI_Comm comm);

int rankOf(MPI_Comm comm);
int sizeOf(MPI_Comm comm);
bool isRoot(MPI_Comm comm);

// Ends every rank of `comm` with exit code `code`, after printing `message` (if not empty) on
// standard error from the calling rank.
[[noreturn]] void abortAll(MPI_Comm comm, int code, const std::string& message);

}  // namespace msim::parallel
