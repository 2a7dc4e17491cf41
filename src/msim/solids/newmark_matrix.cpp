#include "msim/solids/newmark_matrix.hpp"

#include <algorithm>

#include "msim/core/parallel.hpp"

namespace msim::solids {

void NewmarkMatrix::buildPattern(const MassSpringSystem& system) {
  const std::size_t n = system.size();
  std::vector<std::vector<int>> adjacent(n);
  const auto link = [&](int a, int b) {
    adjacent[static_cast<std::size_t>(a)].push_back(b);
    adjacent[static_cast<std::size_t>(b)].push_back(a);
  };
  for (const Spring& s : system.springs) link(s.a, s.b);
  for (const TetrahedronSpring& t : system.tetrahedra)
    for (int i = 0; i < 4; ++i)
      for (int j = i + 1; j < 4; ++j) link(t.v[static_cast<std::size_t>(i)], t.v[static_cast<std::size_t>(j)]);
  std::vector<int> rowStart(n + 1, 0), columns;
  for (std::size_t p = 0; p < n; ++p) {
    std::vector<int>& list = adjacent[p];
    std::sort(list.begin(), list.end());
    list.erase(std::unique(list.begin(), list.end()), list.end());
    columns.insert(columns.end(), list.begin(), list.end());
    rowStart[p + 1] = static_cast<int>(columns.size());
  }
  exact_.resize(columns.size());
  matrix_.setPattern(std::move(rowStart), std::move(columns));
  particles_ = n;
  springs_ = system.springs.size();
  tetrahedra_ = system.tetrahedra.size();
}

void NewmarkMatrix::assemble(const MassSpringSystem& system, const std::vector<SpringTerm>& terms,
                             std::span<const int> incidenceStart, std::span<const std::pair<int, int>> incidence,
                             long incidenceVersion, const ParticleSplit* split) {
  if (particles_ != system.size() || springs_ != system.springs.size() || tetrahedra_ != system.tetrahedra.size()) {
    buildPattern(system);
    incidenceVersion_ = -1;
  }
  if (incidenceVersion != incidenceVersion_) {
    slots_.resize(incidence.size());
    parallelFor(0, system.size(), [&](std::size_t p) {
      for (int j = incidenceStart[p]; j < incidenceStart[p + 1]; ++j) {
        const SpringTerm& t = terms[static_cast<std::size_t>(incidence[static_cast<std::size_t>(j)].first)];
        std::array<int, 4>& slot = slots_[static_cast<std::size_t>(j)];
        for (int i = 0; i < t.count; ++i) {
          const int q = t.node[static_cast<std::size_t>(i)];
          slot[static_cast<std::size_t>(i)] = q == static_cast<int>(p) ? -1 : matrix_.find(static_cast<int>(p), q);
        }
      }
    }, 1024);
    incidenceVersion_ = incidenceVersion;
  }
  const std::span<const int> rowStart = matrix_.rowStart();
  const auto assembleRow = [&](std::size_t p) {
    // The row in double (matrix_ rounds it): the diagonal, and each neighbour's block.
    const std::span<Block> row(exact_.data() + rowStart[p], exact_.data() + rowStart[p + 1]);
    std::fill(row.begin(), row.end(), Block{});
    if (system.pinned[p]) {
      matrix_.setRow(p, Block{1.0, 1.0, 1.0, 0.0, 0.0, 0.0}, row);
      return;
    }
    Block diagonal{system.mass[p], system.mass[p], system.mass[p], 0.0, 0.0, 0.0};
    const auto add = [](Block& to, double w, const Block& S) {
      to.xx += w * S.xx, to.yy += w * S.yy, to.zz += w * S.zz, to.xy += w * S.xy, to.xz += w * S.xz, to.yz += w * S.yz;
    };
    for (int j = incidenceStart[p]; j < incidenceStart[p + 1]; ++j) {
      const auto& [k, place] = incidence[static_cast<std::size_t>(j)];
      const SpringTerm& t = terms[static_cast<std::size_t>(k)];
      const double ownWeight = t.weight[static_cast<std::size_t>(place)];
      const std::array<int, 4>& slot = slots_[static_cast<std::size_t>(j)];
      // c d d^T + c' (I - d d^T) = (c - c') d d^T + c' I
      const Vec3& d = t.direction;
      const double a = t.coefficient - t.sideways, b = t.sideways;
      const Block S{a * d.x() * d.x() + b, a * d.y() * d.y() + b, a * d.z() * d.z() + b,
                    a * d.x() * d.y(),     a * d.x() * d.z(),     a * d.y() * d.z()};
      for (int i = 0; i < t.count; ++i) {
        const int q = t.node[static_cast<std::size_t>(i)];
        if (system.pinned[static_cast<std::size_t>(q)]) continue;
        const double w = ownWeight * t.weight[static_cast<std::size_t>(i)];
        const int entry = slot[static_cast<std::size_t>(i)];
        if (entry < 0) add(diagonal, w, S);
        else add(exact_[static_cast<std::size_t>(entry)], w, S);
      }
    }
    matrix_.setRow(p, diagonal, row);
  };
  if (split) {
    const std::span<const int> owned = split->owned();
    parallelFor(0, owned.size(), [&](std::size_t k) { assembleRow(static_cast<std::size_t>(owned[k])); }, 1024);
  } else {
    parallelFor(0, system.size(), assembleRow, 1024);
  }
}

}  // namespace msim::solids
