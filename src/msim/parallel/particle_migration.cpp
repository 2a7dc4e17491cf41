#include "msim/parallel/particle_migration.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace msim::parallel {

namespace {

// The cell holding `position` (outside the domain: the nearest cell).
template <int D>
IVec<D> cellOf(const Vec<D>& position, const GridBlock<D>& block) {
  IVec<D> cell;
  for (int a = 0; a < D; ++a) {
    const double s = std::floor((position[a] - block.global.origin[a]) / block.global.dx);
    cell[a] = std::isfinite(s) ? static_cast<int>(std::clamp(s, 0.0, double(block.global.res[a] - 1))) : 0;
  }
  return cell;
}

template <int D>
Vec<D> rowPosition(const double* row) {
  Vec<D> x;
  for (int a = 0; a < D; ++a) x[a] = row[a];
  return x;
}

// Offsets of each rank's part from its count.
std::vector<int> offsetsOf(const std::vector<int>& counts) {
  std::vector<int> offsets(counts.size(), 0);
  for (std::size_t r = 1; r < counts.size(); ++r) offsets[r] = offsets[r - 1] + counts[r - 1];
  return offsets;
}

// Rank r's part of `outgoing` is sendCounts[r] values, in rank order; returns what every rank sent
// here, in rank order. Collective.
template <typename T>
std::vector<T> allToAll(const std::vector<T>& outgoing, const std::vector<int>& sendCounts, MPI_Datatype type,
                        MPI_Comm comm) {
  const int ranks = static_cast<int>(sendCounts.size());
  std::vector<int> receiveCounts(ranks, 0);
  MPI_Alltoall(sendCounts.data(), 1, MPI_INT, receiveCounts.data(), 1, MPI_INT, comm);
  const std::vector<int> sendOffsets = offsetsOf(sendCounts), receiveOffsets = offsetsOf(receiveCounts);
  std::vector<T> incoming(static_cast<std::size_t>(receiveOffsets[ranks - 1] + receiveCounts[ranks - 1]));
  MPI_Alltoallv(outgoing.data(), sendCounts.data(), sendOffsets.data(), type, incoming.data(), receiveCounts.data(),
                receiveOffsets.data(), type, comm);
  return incoming;
}

// One particle as a row of floats: position, then the scalar channels, then the vector channels
// (each in name order, the same on every rank).
template <int D>
struct RecordLayout {
  std::vector<std::string> scalars, vectors;
  std::size_t width() const { return D + scalars.size() + D * vectors.size(); }
};

template <int D>
void pack(const Particles<D>& p, const RecordLayout<D>& layout, std::size_t i, float* out) {
  for (int a = 0; a < D; ++a) *out++ = p.positions()[i][a];
  for (const auto& name : layout.scalars) *out++ = p.scalar(name)[i];
  for (const auto& name : layout.vectors)
    for (int a = 0; a < D; ++a) *out++ = p.vector(name)[i][a];
}

template <int D>
void unpack(Particles<D>& p, const RecordLayout<D>& layout, const float* in) {
  Vecf<D> x;
  for (int a = 0; a < D; ++a) x[a] = *in++;
  const std::size_t i = p.append(x);
  for (const auto& name : layout.scalars) p.scalar(name)[i] = *in++;
  for (const auto& name : layout.vectors)
    for (int a = 0; a < D; ++a) p.vector(name)[i][a] = *in++;
}

}  // namespace

template <int D>
int ownerOf(const Vec<D>& position, const GridBlock<D>& block) {
  return block.decomposition.ownerOfCell(cellOf<D>(position, block));
}

template <int D>
std::size_t migrateParticles(Particles<D>& particles, const GridBlock<D>& block, MPI_Comm comm) {
  const int ranks = block.decomposition.ranks();
  const RecordLayout<D> layout{particles.scalarNames(), particles.vectorNames()};
  const std::size_t width = layout.width();
  std::vector<int> owner(particles.size());
  std::vector<int> sendCounts(ranks, 0);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    owner[i] = ownerOf<D>(particles.positions()[i], block);
    if (owner[i] != block.rank) sendCounts[owner[i]] += static_cast<int>(width);
  }
  std::vector<int> cursor = offsetsOf(sendCounts);
  std::vector<float> outgoing(static_cast<std::size_t>(cursor.back() + sendCounts.back()));
  for (std::size_t i = 0; i < particles.size(); ++i)
    if (owner[i] != block.rank) {
      pack(particles, layout, i, outgoing.data() + cursor[owner[i]]);
      cursor[owner[i]] += static_cast<int>(width);
    }
  const std::vector<float> incoming = allToAll(outgoing, sendCounts, MPI_FLOAT, comm);
  const std::size_t sent = outgoing.size() / width;
  particles.removeIf([&](std::size_t i) { return owner[i] != block.rank; });
  for (std::size_t at = 0; at < incoming.size(); at += width) unpack(particles, layout, incoming.data() + at);
  return sent;
}

template <int D>
std::size_t migrateRows(std::vector<double>& rows, int width, const GridBlock<D>& block, MPI_Comm comm) {
  const std::size_t n = rows.size() / static_cast<std::size_t>(width);
  std::vector<int> owner(n), sendCounts(block.decomposition.ranks(), 0);
  for (std::size_t i = 0; i < n; ++i) {
    owner[i] = ownerOf<D>(rowPosition<D>(&rows[i * width]), block);
    if (owner[i] != block.rank) sendCounts[owner[i]] += width;
  }
  std::vector<int> cursor = offsetsOf(sendCounts);
  std::vector<double> outgoing(static_cast<std::size_t>(cursor.back() + sendCounts.back()));
  std::size_t kept = 0;
  for (std::size_t i = 0; i < n; ++i) {
    const double* row = &rows[i * width];
    double* to = &rows[kept * width];  // kept rows move up (never past their own place)
    if (owner[i] == block.rank) {
      ++kept;
    } else {
      to = &outgoing[cursor[owner[i]]];
      cursor[owner[i]] += width;
    }
    std::copy(row, row + width, to);
  }
  rows.resize(kept * width);
  const std::vector<double> incoming = allToAll(outgoing, sendCounts, MPI_DOUBLE, comm);
  rows.insert(rows.end(), incoming.begin(), incoming.end());
  return outgoing.size() / static_cast<std::size_t>(width);
}

template <int D>
std::vector<double> neighbourRows(const std::vector<double>& rows, int width, int reach, const GridBlock<D>& block,
                                  MPI_Comm comm) {
  // The ranks whose own cells, grown by `reach`, overlap this rank's cells, with those boxes.
  const int ranks = block.decomposition.ranks();
  std::vector<std::pair<int, IndexBox<D>>> near;
  for (int r = 0; r < ranks; ++r) {
    IndexBox<D> grown = block.decomposition.ownedCells(r);
    grown.lo -= IVec<D>::Constant(reach);
    grown.hi += IVec<D>::Constant(reach);
    if (r != block.rank && !grown.intersect(block.owned()).empty()) near.emplace_back(r, grown);
  }
  std::vector<std::vector<double>> to(ranks);
  for (std::size_t at = 0; at < rows.size(); at += width) {
    const IVec<D> c = cellOf<D>(rowPosition<D>(&rows[at]), block);
    for (const auto& [r, box] : near) {
      if (box.contains(c)) to[r].insert(to[r].end(), rows.begin() + at, rows.begin() + at + width);
    }
  }
  std::vector<int> sendCounts(ranks, 0);
  std::vector<double> outgoing;
  for (int r = 0; r < ranks; ++r) {
    sendCounts[r] = static_cast<int>(to[r].size());
    outgoing.insert(outgoing.end(), to[r].begin(), to[r].end());
  }
  return allToAll(outgoing, sendCounts, MPI_DOUBLE, comm);
}

std::vector<double> gatherRowsToRoot(const std::vector<double>& rows, MPI_Comm comm) {
  int ranks = 1, rank = 0;
  MPI_Comm_size(comm, &ranks);
  MPI_Comm_rank(comm, &rank);
  const int count = static_cast<int>(rows.size());
  std::vector<int> counts(ranks, 0);
  MPI_Gather(&count, 1, MPI_INT, counts.data(), 1, MPI_INT, 0, comm);
  const std::vector<int> offsets = offsetsOf(counts);
  std::vector<double> all(rank == 0 ? static_cast<std::size_t>(offsets.back() + counts.back()) : 0);
  MPI_Gatherv(rows.data(), count, MPI_DOUBLE, all.data(), counts.data(), offsets.data(), MPI_DOUBLE, 0, comm);
  return all;
}

template int ownerOf<2>(const Vec<2>&, const GridBlock<2>&);
template int ownerOf<3>(const Vec<3>&, const GridBlock<3>&);
template std::size_t migrateRows<2>(std::vector<double>&, int, const GridBlock<2>&, MPI_Comm);
template std::size_t migrateRows<3>(std::vector<double>&, int, const GridBlock<3>&, MPI_Comm);
template std::vector<double> neighbourRows<2>(const std::vector<double>&, int, int, const GridBlock<2>&, MPI_Comm);
template std::vector<double> neighbourRows<3>(const std::vector<double>&, int, int, const GridBlock<3>&, MPI_Comm);
template std::size_t migrateParticles<2>(Particles<2>&, const GridBlock<2>&, MPI_Comm);
template std::size_t migrateParticles<3>(Particles<3>&, const GridBlock<3>&, MPI_Comm);

}  // namespace msim::parallel
