#include "msim/parallel/mpi_domain_split.hpp"

#include "msim/parallel/particle_migration.hpp"

namespace msim::parallel {

MpiDomainSplit::MpiDomainSplit(const GridBlock<3>& block, const numerics::DomainSides<3>& sides,
                               const numerics::PcgSettings& pressureSolve, MPI_Comm comm)
    : block_(block),
      comm_(comm),
      cells_(block, IVec<3>::Zero(), comm),
      faces_(block, comm),
      projection_(block, sides, pressureSolve, comm) {}

void MpiDomainSplit::gather(const Grid<float, 3>& local, Grid<float, 3>& global) {
  Grid<float, 3> all = gatherToRoot(local, block_, comm_);
  if (root()) global = std::move(all);
}

void MpiDomainSplit::gather(const MacGrid<3>& local, MacGrid<3>& global) {
  MacGrid<3> all = gatherToRoot(local, block_, comm_);
  if (root()) global = std::move(all);
}

double MpiDomainSplit::maxOverRanks(double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return value;
}

double MpiDomainSplit::sumOverRanks(double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_SUM, comm_);
  return value;
}

void MpiDomainSplit::sumOverRanks(std::span<double> values) {
  if (!values.empty()) MPI_Allreduce(MPI_IN_PLACE, values.data(), static_cast<int>(values.size()), MPI_DOUBLE, MPI_SUM, comm_);
}

std::size_t MpiDomainSplit::migrate(std::vector<double>& rows, int width) {
  return migrateRows<3>(rows, width, block_, comm_);
}

std::vector<double> MpiDomainSplit::neighbourRows(const std::vector<double>& rows, int width, int reach) {
  return parallel::neighbourRows<3>(rows, width, reach, block_, comm_);
}

std::vector<double> MpiDomainSplit::gatherRows(const std::vector<double>& rows) { return gatherRowsToRoot(rows, comm_); }

SplitSolveStats MpiDomainSplit::project(MacGrid<3>& velocity, Grid<float, 3>& pressure, double dt, double density) {
  return projection_.project(velocity, pressure, dt, density);
}

}  // namespace msim::parallel
