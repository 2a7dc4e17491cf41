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

namespace {

bool mpiRunning() {
  int initialised = 0, finalised = 0;
  MPI_Initialized(&initialised);
  MPI_Finalized(&finalised);
  return initialised && !finalised;
}

}  // namespace

bool launchedByMpi() {
  for (const char* variable : {"OMPI_COMM_WORLD_SIZE", "PMIX_RANK", "PMI_SIZE"})
    if (std::getenv(variable)) return true;
  return false;
}

int worldRank() { return mpiRunning() ? rankOf(MPI_COMM_WORLD) : 0; }

int worldSize() { return mpiRunning() ? sizeOf(MPI_COMM_WORLD) : 1; }

int ranksOnThisNode() {
  if (!mpiRunning()) return 1;
  MPI_Comm node;
  MPI_Comm_split_type(MPI_COMM_WORLD, MPI_COMM_TYPE_SHARED, 0, MPI_INFO_NULL, &node);
  const int n = sizeOf(node);
  MPI_Comm_free(&node);
  return n;
}

bool anyRank(bool flag) {
  if (!mpiRunning()) return flag;
  int mine = flag, any = 0;
  MPI_Allreduce(&mine, &any, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return any != 0;
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
