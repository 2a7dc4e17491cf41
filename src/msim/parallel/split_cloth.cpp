#include "msim/parallel/split_cloth.hpp"

#include <algorithm>
#include <numeric>
#include <stdexcept>

#include "msim/parallel/median_partition.hpp"
#include "msim/parallel/mpi_session.hpp"

namespace msim::parallel {

namespace {

std::vector<char> ownedBy(const std::vector<int>& owner, int rank) {
  std::vector<char> mine(owner.size());
  for (std::size_t p = 0; p < owner.size(); ++p) mine[p] = owner[p] == rank;
  return mine;
}

}  // namespace

SplitCloth::SplitCloth(const std::vector<Vec3>& positions, MPI_Comm comm)
    : SplitCloth(recursiveMedianPartition(positions, sizeOf(comm)), comm) {}

SplitCloth::SplitCloth(std::vector<int> owner, MPI_Comm comm)
    : ParticleSplit(ownedBy(owner, rankOf(comm))), comm_(comm), rank_(rankOf(comm)), ranks_(sizeOf(comm)),
      owner_(std::move(owner)) {
  byOwner_.resize(owner_.size());
  std::iota(byOwner_.begin(), byOwner_.end(), 0);
  std::stable_sort(byOwner_.begin(), byOwner_.end(),
                   [&](int a, int b) { return owner_[static_cast<std::size_t>(a)] < owner_[static_cast<std::size_t>(b)]; });
  counts_.assign(static_cast<std::size_t>(ranks_), 0);
  for (int o : owner_) counts_[static_cast<std::size_t>(o)] += 3;
  offsets_.assign(static_cast<std::size_t>(ranks_), 0);
  for (int r = 1; r < ranks_; ++r)
    offsets_[static_cast<std::size_t>(r)] = offsets_[static_cast<std::size_t>(r - 1)] + counts_[static_cast<std::size_t>(r - 1)];
  schedule_ = twoPhaseSchedule(scheduledItems_, owner_, ranks_);  // for no items
  send_.resize(static_cast<std::size_t>(counts_[static_cast<std::size_t>(rank_)]));
  receive_.resize(3 * owner_.size());
}

std::span<const int> SplitCloth::owned() const {
  const auto r = static_cast<std::size_t>(rank_);
  return {byOwner_.data() + offsets_[r] / 3, static_cast<std::size_t>(counts_[r] / 3)};
}

void SplitCloth::shareOwned(double* values) const {
  const std::span<const int> mine = owned();
  for (std::size_t k = 0; k < mine.size(); ++k)
    std::copy_n(values + 3 * static_cast<std::size_t>(mine[k]), 3, send_.data() + 3 * k);
  MPI_Allgatherv(send_.data(), counts_[static_cast<std::size_t>(rank_)], MPI_DOUBLE, receive_.data(), counts_.data(),
                 offsets_.data(), MPI_DOUBLE, comm_);
  for (std::size_t k = 0; k < byOwner_.size(); ++k)
    std::copy_n(receive_.data() + 3 * k, 3, values + 3 * static_cast<std::size_t>(byOwner_[k]));
}

// Every process's part in every process's hands, added in rank order: MPI_Allreduce may add in an
// order that differs between processes, and processes that disagreed by a rounding would take
// different CG steps.
double SplitCloth::sum(double local) const {
  parts_.resize(static_cast<std::size_t>(ranks_));
  MPI_Allgather(&local, 1, MPI_DOUBLE, parts_.data(), 1, MPI_DOUBLE, comm_);
  return std::accumulate(parts_.begin(), parts_.end(), 0.0);
}

void SplitCloth::gatherRows(std::vector<double>& rows, int width) const {
  rows = joinedFromAll(rows, comm_);
  if (rows.size() % static_cast<std::size_t>(width) != 0) throw std::logic_error("gatherRows: rows of another width");
}

void SplitCloth::gaussSeidel(const std::vector<std::array<int, 4>>& items, std::vector<Vec3>& v,
                             const std::function<void(std::size_t)>& respond) const {
  // The repulsions' passes of one inner step run over the same contacts: their schedule serves all.
  if (items != scheduledItems_) {
    schedule_ = twoPhaseSchedule(items, owner_, ranks_);
    scheduledItems_ = items;
  }
  respondTwoPhase(schedule_, items, v, rank_, comm_, [&](int item, std::vector<Vec3>&) { respond(static_cast<std::size_t>(item)); });
}

}  // namespace msim::parallel
