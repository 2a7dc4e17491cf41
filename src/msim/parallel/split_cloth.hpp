#pragma once
// A cloth (or any mass-spring system) split among the processes of an MPI communicator after
// Selle ch. 8.2: the particles are cut by recursiveMedianPartition at their starting positions,
// fixed for the run; every process stores every particle. shareOwned() exchanges the rows each
// process computed (MPI_Allgatherv of the owners' values), sum() adds one number per process in
// rank order (the same bits everywhere, so all processes take the same CG steps), gatherRows()
// joins what each process found (MPI_Allgatherv), gaussSeidel() runs a collision pass in the two
// phases of two_phase_collisions.hpp.
#include <mpi.h>

#include <vector>

#include "msim/parallel/two_phase_collisions.hpp"
#include "msim/solids/particle_split.hpp"

namespace msim::parallel {

class SplitCloth final : public solids::ParticleSplit {
 public:
  // Collective; the processes pass the same positions. The process count must be a power of two
  // (std::invalid_argument otherwise).
  SplitCloth(const std::vector<Vec3>& positions, MPI_Comm comm);

  std::span<const int> owned() const override;
  void shareOwned(double* values) const override;
  double sum(double local) const override;
  void gatherRows(std::vector<double>& rows, int width) const override;
  void gaussSeidel(const std::vector<std::array<int, 4>>& items, std::vector<Vec3>& v,
                   const std::function<void(std::size_t)>& respond) const override;

 private:
  SplitCloth(std::vector<int> owner, MPI_Comm comm);

  MPI_Comm comm_;
  int rank_ = 0, ranks_ = 1;
  std::vector<int> owner_;
  std::vector<int> byOwner_;  // every particle, by owner then index: the order of shareOwned's buffer
  std::vector<int> counts_, offsets_;  // doubles per process in that buffer
  mutable std::vector<double> send_, receive_, parts_;  // shareOwned's and sum()'s buffers
  mutable std::vector<std::array<int, 4>> scheduledItems_;  // the items schedule_ is for
  mutable TwoPhaseSchedule schedule_;
};

}  // namespace msim::parallel
