#include "msim/parallel/mpi_domain_split.hpp"

namespace msim::parallel {

MpiDomainSplit::MpiDomainSplit(const GridBlock<3>& block, const numerics::DomainSides<3>& sides,
                               const numerics::PcgSettings& pressureSolve, MPI_Comm comm)
    : block_(block),
      comm_(comm),
      cells_(block, IVec<3>::Zero(), comm),
      faces_(block, comm),
      projection_(block, sides, pressureSolve, comm) {}

double MpiDomainSplit::maxOverRanks(double value) {
  MPI_Allreduce(MPI_IN_PLACE, &value, 1, MPI_DOUBLE, MPI_MAX, comm_);
  return value;
}

SplitSolveStats MpiDomainSplit::project(MacGrid<3>& velocity, double dt, double density) {
  const DistributedProjectionStats s = projection_.project(velocity, dt, density);
  return {s.iterations, s.relativeResidual, s.converged};
}

}  // namespace msim::parallel
