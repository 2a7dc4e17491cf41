// GoogleTest under MPI: every rank runs every test (the tests are collective), rank 0 reports,
// and the program fails on every rank if a test failed on any.
#include <gtest/gtest.h>
#include <mpi.h>

#include "msim/parallel/mpi_session.hpp"

int main(int argc, char** argv) {
  msim::parallel::MpiSession mpi(argc, argv);
  ::testing::InitGoogleTest(&argc, argv);
  if (!msim::parallel::isRoot(MPI_COMM_WORLD)) {
    auto& listeners = ::testing::UnitTest::GetInstance()->listeners();
    delete listeners.Release(listeners.default_result_printer());
  }
  int failed = RUN_ALL_TESTS() != 0, anyFailed = 0;
  MPI_Allreduce(&failed, &anyFailed, 1, MPI_INT, MPI_MAX, MPI_COMM_WORLD);
  return anyFailed;
}
