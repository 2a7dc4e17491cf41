#include "msim/parallel/mpi_session.hpp"

#include <cstdio>
#include <cstdlib>

#include "msim/core/error.hpp"

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

long fromRankZero(long value) {
  if (mpiRunning()) MPI_Bcast(&value, 1, MPI_LONG, 0, MPI_COMM_WORLD);
  return value;
}

std::vector<double> joinedFromAll(const std::vector<double>& mine, MPI_Comm comm) {
  const int ranks = sizeOf(comm);
  const int count = static_cast<int>(mine.size());
  std::vector<int> counts(static_cast<std::size_t>(ranks)), offsets(static_cast<std::size_t>(ranks), 0);
  MPI_Allgather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r)
    offsets[static_cast<std::size_t>(r)] = offsets[static_cast<std::size_t>(r - 1)] + counts[static_cast<std::size_t>(r - 1)];
  std::vector<double> all(static_cast<std::size_t>(offsets.back() + counts.back()));
  MPI_Allgatherv(mine.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, comm);
  return all;
}

void agreeOnFailure(std::exception_ptr local, MPI_Comm comm) {
  if (!mpiRunning()) {
    if (local) std::rethrow_exception(local);
    return;
  }
  // The kind of this rank's failure (0: none, 1: other, 2: input, 3: simulation) and its message.
  int kind = 0;
  std::string message;
  if (local) {
    try {
      std::rethrow_exception(local);
    } catch (const InputError& e) {
      kind = 2, message = e.what();
    } catch (const SimulationError& e) {
      kind = 3, message = e.what();
    } catch (const std::exception& e) {
      kind = 1, message = e.what();
    } catch (...) {
      kind = 1, message = "unknown error";
    }
  }
  const int rank = rankOf(comm), big = sizeOf(comm);
  int first = kind ? rank : big;
  MPI_Allreduce(MPI_IN_PLACE, &first, 1, MPI_INT, MPI_MIN, comm);
  if (first == big) return;
  // The lowest failing rank tells every rank what went wrong.
  int header[2] = {kind, static_cast<int>(message.size())};
  MPI_Bcast(header, 2, MPI_INT, first, comm);
  message.resize(static_cast<std::size_t>(header[1]));
  MPI_Bcast(message.data(), header[1], MPI_CHAR, first, comm);
  if (header[0] == 2) throw InputError(message);
  if (header[0] == 3) throw SimulationError(message);
  throw std::runtime_error(message);
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
