#include "msim/parallel/particle_migration.hpp"

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

namespace msim::parallel {

template <int D>
int ownerOf(const Vecf<D>& position, const GridBlock<D>& block) {
  IVec<D> cell;
  for (int a = 0; a < D; ++a) {
    const double s = std::floor((double(position[a]) - block.global.origin[a]) / block.global.dx);
    cell[a] = std::isfinite(s) ? static_cast<int>(std::clamp(s, -1.0, double(block.global.res[a]))) : 0;
  }
  return block.decomposition.ownerOfCell(cell);
}

namespace {

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
std::size_t migrateParticles(Particles<D>& particles, const GridBlock<D>& block, MPI_Comm comm) {
  const int ranks = block.decomposition.ranks();
  const RecordLayout<D> layout{particles.scalarNames(), particles.vectorNames()};
  const std::size_t width = layout.width();
  std::vector<int> owner(particles.size());
  std::vector<int> sendCounts(ranks, 0), receiveCounts(ranks, 0);
  for (std::size_t i = 0; i < particles.size(); ++i) {
    owner[i] = ownerOf<D>(particles.positions()[i], block);
    if (owner[i] != block.rank) sendCounts[owner[i]] += static_cast<int>(width);
  }
  std::vector<int> sendOffsets(ranks, 0), receiveOffsets(ranks, 0);
  for (int r = 1; r < ranks; ++r) sendOffsets[r] = sendOffsets[r - 1] + sendCounts[r - 1];
  std::vector<float> outgoing(static_cast<std::size_t>(sendOffsets[ranks - 1] + sendCounts[ranks - 1]));
  std::vector<int> cursor = sendOffsets;
  for (std::size_t i = 0; i < particles.size(); ++i)
    if (owner[i] != block.rank) {
      pack(particles, layout, i, outgoing.data() + cursor[owner[i]]);
      cursor[owner[i]] += static_cast<int>(width);
    }
  MPI_Alltoall(sendCounts.data(), 1, MPI_INT, receiveCounts.data(), 1, MPI_INT, comm);
  for (int r = 1; r < ranks; ++r) receiveOffsets[r] = receiveOffsets[r - 1] + receiveCounts[r - 1];
  std::vector<float> incoming(static_cast<std::size_t>(receiveOffsets[ranks - 1] + receiveCounts[ranks - 1]));
  MPI_Alltoallv(outgoing.data(), sendCounts.data(), sendOffsets.data(), MPI_FLOAT, incoming.data(),
                receiveCounts.data(), receiveOffsets.data(), MPI_FLOAT, comm);
  const std::size_t sent = outgoing.size() / width;
  particles.removeIf([&](std::size_t i) { return owner[i] != block.rank; });
  for (std::size_t at = 0; at < incoming.size(); at += width) unpack(particles, layout, incoming.data() + at);
  return sent;
}

template int ownerOf<2>(const Vecf<2>&, const GridBlock<2>&);
template int ownerOf<3>(const Vecf<3>&, const GridBlock<3>&);
template std::size_t migrateParticles<2>(Particles<2>&, const GridBlock<2>&, MPI_Comm);
template std::size_t migrateParticles<3>(Particles<3>&, const GridBlock<3>&, MPI_Comm);

}  // namespace msim::parallel
