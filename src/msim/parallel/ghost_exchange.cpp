#include "msim/parallel/ghost_exchange.hpp"

#include <algorithm>
#include <cstring>

#include "msim/core/grid_window.hpp"

namespace msim::parallel {

namespace {

// f(offset of the row's first sample in `grid`, position of that row in the box's buffer, row
// length) for every row along axis 0 of `box` (global indices; grid sample 0 is global `origin`).
template <typename T, int D, typename F>
void forEachBoxRow(const Grid<T, D>& grid, const IVec<D>& origin, const IndexBox<D>& box, F&& f) {
  if (box.empty()) return;
  const IVec<D> size = box.size();
  const std::size_t rowLength = static_cast<std::size_t>(size[0]);
  std::size_t rows = 1;
  for (int a = 1; a < D; ++a) rows *= static_cast<std::size_t>(size[a]);
  for (std::size_t row = 0; row < rows; ++row) {
    std::size_t rest = row;
    std::ptrdiff_t offset = (box.lo[0] - origin[0]) * grid.stride(0);
    for (int a = 1; a < D; ++a) {
      const auto c = static_cast<std::ptrdiff_t>(rest % static_cast<std::size_t>(size[a]));
      rest /= static_cast<std::size_t>(size[a]);
      offset += (box.lo[a] - origin[a] + c) * grid.stride(a);
    }
    f(static_cast<std::size_t>(offset), row * rowLength, rowLength);
  }
}

}  // namespace

template <typename T, int D>
void packBox(const Grid<T, D>& local, const IVec<D>& origin, const IndexBox<D>& box, T* out) {
  const T* data = local.data().data();
  forEachBoxRow(local, origin, box,
                [&](std::size_t at, std::size_t to, std::size_t n) { std::memcpy(out + to, data + at, n * sizeof(T)); });
}

template <typename T, int D>
void unpackBox(Grid<T, D>& local, const IVec<D>& origin, const IndexBox<D>& box, const T* in) {
  T* data = local.data().data();
  forEachBoxRow(local, origin, box,
                [&](std::size_t at, std::size_t from, std::size_t n) { std::memcpy(data + at, in + from, n * sizeof(T)); });
}

template <typename T, int D>
GhostExchange<T, D>::GhostExchange(const GridBlock<D>& block, const IVec<D>& extra, MPI_Comm comm)
    : origin_(block.cellOrigin()), comm_(comm) {
  const IndexBox<D> mineOwned = block.ownedSamples(block.rank, extra);
  const IndexBox<D> mineStored = block.storedSamples(block.rank, extra);
  for (int r = 0; r < block.decomposition.ranks(); ++r) {
    if (r == block.rank) continue;
    const IndexBox<D> receive = block.ownedSamples(r, extra).intersect(mineStored);
    const IndexBox<D> send = mineOwned.intersect(block.storedSamples(r, extra));
    // Stored boxes are the owned ones grown by the same width, so the two are empty together.
    if (receive.empty() && send.empty()) continue;
    Peer p{r, send, receive, {}, {}};
    p.sendBuffer.resize(static_cast<std::size_t>(std::max(0LL, send.count())));
    p.receiveBuffer.resize(static_cast<std::size_t>(std::max(0LL, receive.count())));
    peers_.push_back(std::move(p));
  }
  requests_.resize(2 * peers_.size());
}

template <typename T, int D>
void GhostExchange<T, D>::exchange(Grid<T, D>& local) {
  constexpr int kTag = 17;
  const std::size_t n = peers_.size();
  for (std::size_t i = 0; i < n; ++i) {
    Peer& p = peers_[i];
    MPI_Irecv(p.receiveBuffer.data(), static_cast<int>(p.receiveBuffer.size() * sizeof(T)), MPI_BYTE, p.rank, kTag,
              comm_, &requests_[i]);
  }
  for (std::size_t i = 0; i < n; ++i) {
    Peer& p = peers_[i];
    packBox(local, origin_, p.send, p.sendBuffer.data());
    MPI_Isend(p.sendBuffer.data(), static_cast<int>(p.sendBuffer.size() * sizeof(T)), MPI_BYTE, p.rank, kTag, comm_,
              &requests_[n + i]);
  }
  MPI_Waitall(static_cast<int>(requests_.size()), requests_.data(), MPI_STATUSES_IGNORE);
  for (Peer& p : peers_) unpackBox(local, origin_, p.receive, p.receiveBuffer.data());
}

template <typename T, int D>
std::size_t GhostExchange<T, D>::receivedSamples() const {
  std::size_t n = 0;
  for (const Peer& p : peers_) n += p.receiveBuffer.size();
  return n;
}

template <int D>
std::size_t MacGhostExchange<D>::receivedSamples() const {
  std::size_t n = 0;
  for (const auto& c : components_) n += c.receivedSamples();
  return n;
}

template <int D>
MacGhostExchange<D>::MacGhostExchange(const GridBlock<D>& block, MPI_Comm comm) {
  for (int a = 0; a < D; ++a) components_.emplace_back(block, IVec<D>::Unit(a), comm);
}

template <int D>
void MacGhostExchange<D>::exchange(MacGrid<D>& local) {
  for (int a = 0; a < D; ++a) components_[a].exchange(local.component(a));
}

template <typename T, int D>
Grid<T, D> gatherToRoot(const Grid<T, D>& local, const GridBlock<D>& block, MPI_Comm comm) {
  const IVec<D> extra = extraSamples(local);
  const int ranks = block.decomposition.ranks();
  const IndexBox<D> mine = block.ownedSamples(block.rank, extra);
  std::vector<T> packed(static_cast<std::size_t>(mine.count()));
  packBox(local, block.cellOrigin(), mine, packed.data());
  std::vector<int> counts(ranks), displacements(ranks);
  for (int r = 0; r < ranks; ++r) counts[r] = static_cast<int>(block.ownedSamples(r, extra).count() * sizeof(T));
  for (int r = 1; r < ranks; ++r) displacements[r] = displacements[r - 1] + counts[r - 1];
  const bool root = block.rank == 0;
  std::vector<T> all(root ? static_cast<std::size_t>(displacements[ranks - 1] + counts[ranks - 1]) / sizeof(T) : 0);
  MPI_Gatherv(packed.data(), static_cast<int>(packed.size() * sizeof(T)), MPI_BYTE, all.data(), counts.data(),
              displacements.data(), MPI_BYTE, 0, comm);
  if (!root) return {};
  Grid<T, D> global(block.global, block.global.res + extra, local.offset());
  for (int r = 0; r < ranks; ++r)
    unpackBox(global, IVec<D>::Zero().eval(), block.ownedSamples(r, extra), all.data() + displacements[r] / sizeof(T));
  return global;
}

template <int D>
MacGrid<D> gatherToRoot(const MacGrid<D>& local, const GridBlock<D>& block, MPI_Comm comm) {
  MacGrid<D> global(block.rank == 0 ? block.global : GridSpec<D>());
  for (int a = 0; a < D; ++a) {
    Grid<float, D> g = gatherToRoot(local.component(a), block, comm);
    if (block.rank == 0) global.component(a) = std::move(g);
  }
  return block.rank == 0 ? global : MacGrid<D>();
}

template <typename T, int D>
Grid<T, D> localPart(const Grid<T, D>& global, const GridBlock<D>& block) {
  const IVec<D> extra = extraSamples(global);
  const GridSpec<D> spec = block.localSpec();
  Grid<T, D> local(spec, spec.res + extra, global.offset());
  forEachWindowRow<D>(global, block.cellOrigin(), local,
                      [](const T* row, T* localRow, std::size_t n) { std::copy_n(row, n, localRow); });
  return local;
}

template <int D>
MacGrid<D> localPart(const MacGrid<D>& global, const GridBlock<D>& block) {
  MacGrid<D> local(block.localSpec());
  for (int a = 0; a < D; ++a) local.component(a) = localPart(global.component(a), block);
  return local;
}

#define MSIM_INSTANTIATE(T, D)                                                                      \
  template class GhostExchange<T, D>;                                                               \
  template void packBox<T, D>(const Grid<T, D>&, const IVec<D>&, const IndexBox<D>&, T*);           \
  template void unpackBox<T, D>(Grid<T, D>&, const IVec<D>&, const IndexBox<D>&, const T*);         \
  template Grid<T, D> gatherToRoot<T, D>(const Grid<T, D>&, const GridBlock<D>&, MPI_Comm);         \
  template Grid<T, D> localPart<T, D>(const Grid<T, D>&, const GridBlock<D>&);
MSIM_INSTANTIATE(float, 2)
MSIM_INSTANTIATE(float, 3)
MSIM_INSTANTIATE(double, 2)
MSIM_INSTANTIATE(double, 3)
#undef MSIM_INSTANTIATE
template class MacGhostExchange<2>;
template class MacGhostExchange<3>;
template MacGrid<2> gatherToRoot<2>(const MacGrid<2>&, const GridBlock<2>&, MPI_Comm);
template MacGrid<3> gatherToRoot<3>(const MacGrid<3>&, const GridBlock<3>&, MPI_Comm);
template MacGrid<2> localPart<2>(const MacGrid<2>&, const GridBlock<2>&);
template MacGrid<3> localPart<3>(const MacGrid<3>&, const GridBlock<3>&);

}  // namespace msim::parallel
