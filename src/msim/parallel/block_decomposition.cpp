#include "msim/parallel/block_decomposition.hpp"

#include <fmt/format.h>

#include <algorithm>
#include <limits>

#include "msim/core/error.hpp"

namespace msim::parallel {

namespace {

template <int D>
std::string cellsText(const IVec<D>& v) {
  std::string s;
  for (int a = 0; a < D; ++a) s += (a ? "x" : "") + std::to_string(v[a]);
  return s;
}

// Cells of the faces between blocks: along axis a, (p_a - 1) planes of the other axes' cells.
template <int D>
double interfaceArea(const IVec<D>& res, const IVec<D>& blocks) {
  double area = 0.0;
  for (int a = 0; a < D; ++a) {
    double plane = 1.0;
    for (int b = 0; b < D; ++b)
      if (b != a) plane *= res[b];
    area += (blocks[a] - 1) * plane;
  }
  return area;
}

// Every lattice with product `ranks`, axis by axis (divisors of what is left), keeping the one
// of least interface area whose blocks hold minCells cells along each axis.
template <int D>
void searchLattices(const IVec<D>& res, int ranks, int minCells, int axis, IVec<D>& blocks, IVec<D>& best,
                    double& bestArea) {
  if (axis == D - 1) {
    blocks[axis] = ranks;
    for (int a = 0; a < D; ++a)
      if (res[a] / blocks[a] < minCells) return;
    const double area = interfaceArea<D>(res, blocks);
    if (area < bestArea) {
      bestArea = area;
      best = blocks;
    }
    return;
  }
  for (int p = 1; p <= ranks; ++p) {
    if (ranks % p != 0) continue;
    blocks[axis] = p;
    searchLattices<D>(res, ranks / p, minCells, axis + 1, blocks, best, bestArea);
  }
}

template <int D>
void checkLattice(const IVec<D>& res, const IVec<D>& blocks, int minCells, const std::string& key) {
  for (int a = 0; a < D; ++a)
    if (blocks[a] < 1 || res[a] / blocks[a] < minCells)
      throw InputError(fmt::format("{}: {} blocks cannot split the {} cells of the grid with at least {} cells per "
                                   "block along each axis (the ghost layers the schemes need)",
                                   key, cellsText<D>(blocks), cellsText<D>(res), minCells));
}

}  // namespace

template <int D>
BlockDecomposition<D>::BlockDecomposition(const IVec<D>& res, int ranks, int minCells, const std::string& key)
    : res_(res) {
  if (ranks < 1) throw InputError(fmt::format("{}: expected at least one process, got {}", key, ranks));
  IVec<D> blocks = IVec<D>::Ones(), best = IVec<D>::Zero();
  double bestArea = std::numeric_limits<double>::infinity();
  searchLattices<D>(res, ranks, minCells, 0, blocks, best, bestArea);
  if (best.isZero())
    throw InputError(fmt::format("{}: {} processes cannot split the {} cells of the grid: every split leaves a block "
                                 "thinner than {} cells (the ghost layers the schemes need); use fewer processes "
                                 "or a finer grid",
                                 key, ranks, cellsText<D>(res), minCells));
  blocks_ = best;
}

template <int D>
BlockDecomposition<D>::BlockDecomposition(const IVec<D>& res, const IVec<D>& blocks, int minCells,
                                          const std::string& key)
    : res_(res), blocks_(blocks) {
  checkLattice<D>(res, blocks, minCells, key);
}

template <int D>
IVec<D> BlockDecomposition<D>::blockCoord(int rank) const {
  IVec<D> c;
  for (int a = 0; a < D; ++a) {
    c[a] = rank % blocks_[a];
    rank /= blocks_[a];
  }
  return c;
}

template <int D>
int BlockDecomposition<D>::rankAt(const IVec<D>& c) const {
  int rank = 0, stride = 1;
  for (int a = 0; a < D; ++a) {
    if (c[a] < 0 || c[a] >= blocks_[a]) return -1;
    rank += c[a] * stride;
    stride *= blocks_[a];
  }
  return rank;
}

// Block k of p along an axis of n cells holds [k n / p, (k + 1) n / p): sizes differ by one at most.
template <int D>
IndexBox<D> BlockDecomposition<D>::ownedCells(int rank) const {
  const IVec<D> c = blockCoord(rank);
  IndexBox<D> box;
  for (int a = 0; a < D; ++a) {
    const long long n = res_[a], p = blocks_[a];
    box.lo[a] = static_cast<int>(c[a] * n / p);
    box.hi[a] = static_cast<int>((c[a] + 1) * n / p);
  }
  return box;
}

// Block k holds cell c when floor(k n / p) <= c < floor((k + 1) n / p), i.e. k = floor(((c + 1) p - 1) / n).
template <int D>
int BlockDecomposition<D>::ownerOfCell(const IVec<D>& c) const {
  IVec<D> k;
  for (int a = 0; a < D; ++a) {
    const long long n = res_[a], p = blocks_[a], cell = std::clamp<long long>(c[a], 0, n - 1);
    k[a] = static_cast<int>(((cell + 1) * p - 1) / n);
  }
  return rankAt(k);
}

template class BlockDecomposition<2>;
template class BlockDecomposition<3>;

}  // namespace msim::parallel
