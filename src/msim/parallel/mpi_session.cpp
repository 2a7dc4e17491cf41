#include "msim/parallel/mpi_session.hpp"

#include <cstdio>
#include <cstdlib>

namespace msim::parallel {

MpiSession::MpiSession(int& argc, char**& argv) {
  int initialised = 0;
  MPI_Initialized(&initialised);
  if (initialised) return;
  // oneTBB's workers never call MPI: only the thread that initialised MPI communicates.
  int provided = 0;
  MPI_Init_thread(&argc, &argv, MPI_THREAD_FUNNELED, &provided);
}

MpiSession::~MpiSession() {
  int finalised = 0;
  MPI_Finalized(&finalised);
  if (!finalised) MPI_Finalize();
}

int rankOf(MPI_Comm comm) {
  int r = 0;
  MPI_Comm_rank(comm, &r);
  return r;
}

int sizeOf(MPI_Comm comm) {
  int n = 1;
  MPI_Comm_size(comm, &n);
  return n;
}

bool isRoot(MPI_Comm comm) { return rankOf(comm) == 0; }

void abortAll(MPI_Comm comm, int code, const std::string& message) {
  if (!message.empty()) std::fprintf(stderr, "msim (rank %d): %s\n", rankOf(comm), message.c_str());
  std::fflush(stderr);
  MPI_Abort(comm, code);
  std::abort();  // MPI_Abort does not return; this keeps [[noreturn]] honest
}

}  // namespace msim::parallel
