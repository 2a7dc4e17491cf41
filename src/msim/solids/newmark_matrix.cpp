#include "msim/solids/newmark_matrix.hpp"

#include <algorithm>

namespace msim::solids {

void NewmarkMatrix::buildPattern(const MassSpringSystem& system) {
  const std::size_t n = system.size();
  std::vector<std::vector<int>> adjacent(n);
  for (std::size_t p = 0; p < n; ++p) adjacent[p].push_back(static_cast<int>(p));
  const auto link = [&](int a, int b) {
    adjacent[static_cast<std::size_t>(a)].push_back(b);
    adjacent[static_cast<std::size_t>(b)].push_back(a);
  };
  for (const Spring& s : system.springs) link(s.a, s.b);
  for (const TetrahedronSpring& t : system.tetrahedra)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) link(t.v[static_cast<std::size_t>(i)], t.v[static_cast<std::size_t>(j)]);
  neighbourStart_.assign(n + 1, 0);
  neighbours_.clear();
  for (std::size_t p = 0; p < n; ++p) {
    std::vector<int>& list = adjacent[p];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    neighbours_.insert(neighbours_.end(), list.begin(), list.end());
    neighbourStart_[p + 1] = static_cast<int>(neighbours_.size());
  }
  // Row 3 p + k holds columns 3 q + l for each neighbour q of p (sorted), l = 0..2.
  const auto rows = static_cast<Eigen::Index>(3 * n);
  matrix_ = numerics::SparseRowMatrix(rows, rows);
  matrix_.resizeNonZeros(static_cast<Eigen::Index>(9 * neighbours_.size()));
  int* outer = matrix_.outerIndexPtr();
  int* inner = matrix_.innerIndexPtr();
  int entry = 0;
  for (std::size_t p = 0; p < n; ++p)
    for (int k = 0; k < 3; ++k) {
      outer[3 * p + static_cast<std::size_t>(k)] = entry;
      for (int e = neighbourStart_[p]; e < neighbourStart_[p + 1]; ++e)
        for (int l = 0; l < 3; ++l) inner[entry++] = 3 * neighbours_[static_cast<std::size_t>(e)] + l;
    }
  outer[rows] = entry;
  particles_ = n;
  springs_ = system.springs.size();
  tetrahedra_ = system.tetrahedra.size();
}

int NewmarkMatrix::blockOffset(int i, int j) const {
  const auto begin = neighbours_.begin() + neighbourStart_[static_cast<std::size_t>(i)];
  const auto end = neighbours_.begin() + neighbourStart_[static_cast<std::size_t>(i) + 1];
  return 3 * static_cast<int>(std::lower_bound(begin, end, j) - begin);
}

void NewmarkMatrix::assemble(const MassSpringSystem& system, const std::vector<SpringTerm>& terms) {
  if (particles_ != system.size() || springs_ != system.springs.size() || tetrahedra_ != system.tetrahedra.size())
    buildPattern(system);
  const int* outer = matrix_.outerIndexPtr();
  double* value = matrix_.valuePtr();
  std::fill(value, value + matrix_.nonZeros(), 0.0);
  for (std::size_t p = 0; p < system.size(); ++p) {
    const int self = blockOffset(static_cast<int>(p), static_cast<int>(p));
    for (int k = 0; k < 3; ++k) value[outer[3 * p + static_cast<std::size_t>(k)] + self + k] = system.pinned[p] ? 1.0 : system.mass[p];
  }
  for (const SpringTerm& t : terms) {
    // c d d^T + c' (I - d d^T) = (c - c') d d^T + c' I
    const Eigen::Matrix3d block =
        (t.coefficient - t.sideways) * t.direction * t.direction.transpose() + t.sideways * Eigen::Matrix3d::Identity();
    for (int a = 0; a < t.count; ++a) {
      const int i = t.node[static_cast<std::size_t>(a)];
      if (system.pinned[static_cast<std::size_t>(i)]) continue;
      for (int b = 0; b < t.count; ++b) {
        const int j = t.node[static_cast<std::size_t>(b)];
        if (system.pinned[static_cast<std::size_t>(j)]) continue;
        const double w = t.weight[static_cast<std::size_t>(a)] * t.weight[static_cast<std::size_t>(b)];
        const int offset = blockOffset(i, j);
        for (int k = 0; k < 3; ++k) {
          double* row = value + outer[3 * i + k] + offset;
          for (int l = 0; l < 3; ++l) row[l] += w * block(k, l);
        }
      }
    }
  }
}

}  // namespace msim::solids
