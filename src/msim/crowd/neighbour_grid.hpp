#pragma once
// Uniform-grid neighbour search for 2D points (a cell list built by counting sort): O(n) to
// build, no allocation on rebuilds of similar size, and neighbours of a point are found in the
// 3x3 cells around it. Used by pairwise collision resolution, ORCA and the crowd metrics.
#include <algorithm>
#include <cmath>
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::crowd {

class NeighbourGrid {
 public:
  // Buckets the points into square cells of side `cellSize` (> 0) covering their bounds. Queries
  // with a radius <= cellSize are exact; larger radii visit more cells. Points must be finite.
  // Parallel; the bucket order is the input order within each cell (deterministic).
  void build(std::span<const Vecf<2>> points, float cellSize);

  float cellSize() const { return cellSize_; }
  std::size_t size() const { return cellOf_.size(); }

  // Calls f(j) for every point j != i with |x_j - x_i| < radius (i is an index of the built
  // points). Visits in cell order, then input order.
  template <typename F>
  void forEachNeighbour(std::size_t i, float radius, F&& f) const;
  // Calls f(j) for every built point j with |x_j - x| < radius.
  template <typename F>
  void forEachWithin(const Vecf<2>& x, float radius, F&& f) const;
  // Calls f(first, last) for each row of cells a disc of the radius around x touches, bottom to
  // top, with the slots [first, last) of cellOrder() in that row's touched cells (contiguous, as
  // cells are row-major): a superset of the built points within the radius (no distance test),
  // for callers that keep their own cell-ordered copies.
  template <typename F>
  void forEachSlotRowNear(const Vecf<2>& x, float radius, F&& f) const;

  // The built points (a copy, in input order).
  std::span<const Vecf<2>> points() const { return points_; }
  // Point indices in cell order (row-major cells, input order within a cell): iterating agents
  // in this order keeps neighbouring agents' data in cache.
  std::span<const std::uint32_t> cellOrder() const { return order_; }

  // The cell structure, for callers that sweep cell by cell over their own cell-ordered copies
  // of per-point data: cells are row-major (cellsX() per row, cellsY() rows, x fastest); the
  // points of cell c are the slots [cellStarts()[c], cellStarts()[c + 1]) of cellOrder() and
  // sortedPoints(). Every point lies in the cell of its coordinates (the grid covers the bounds),
  // so all points within cellSize() of a point are in the 3x3 cells around its own.
  int cellsX() const { return nx_; }
  int cellsY() const { return ny_; }
  std::span<const std::uint32_t> cellStarts() const { return cellStart_; }
  // points()[cellOrder()[k]] for each slot k.
  std::span<const Vecf<2>> sortedPoints() const { return sorted_; }

  // The slots of the (up to) 3x3 cells around a cell: [lo[q], hi[q]) for q < count, one
  // contiguous range per row.
  struct Stencil {
    std::uint32_t lo[3], hi[3];
    int count = 0;
    std::size_t cell = 0;      // the centre cell, cy * cellsX() + cx
    int x0, x1, y0, y1;        // the stencil's cells: x0..x1 in rows y0..y1 (inclusive)
  };
  // For each non-empty cell of the rows [row0, row1): f(first, last, stencil) with the cell's
  // slots [first, last) and its stencil, which holds every point within cellSize() of them.
  template <typename F>
  void forEachCellInRows(int row0, int row1, F&& f) const;

 private:
  // Calls f(k) for each slot k of order_ in the cells a disc of the radius around x touches.
  template <typename F>
  void visitCells(const Vecf<2>& x, float radius, F&& f) const;

  float cellSize_ = 1.0f;
  Vecf<2> origin_ = Vecf<2>::Zero();
  int nx_ = 0, ny_ = 0;
  std::vector<Vecf<2>> points_;
  std::vector<std::uint32_t> cellOf_;     // cell of each point
  std::vector<std::uint32_t> cellStart_;  // points of cell c: order_[cellStart_[c], cellStart_[c+1])
  std::vector<std::uint32_t> order_;
  std::vector<Vecf<2>> sorted_;  // points_[order_[k]]: the distance tests stream through memory
  std::vector<std::uint32_t> blockCount_;  // build scratch: per-block cell counts, then offsets
  std::vector<std::uint32_t> spanTotal_;   // build scratch: points before each span of cells
};

template <typename F>
void NeighbourGrid::forEachSlotRowNear(const Vecf<2>& x, float radius, F&& f) const {
  if (nx_ == 0) return;
  const Vecf<2> rel = (x - origin_) / cellSize_;
  const float reach = radius / cellSize_;
  const int i0 = std::max(0, static_cast<int>(std::floor(rel.x() - reach)));
  const int i1 = std::min(nx_ - 1, static_cast<int>(std::floor(rel.x() + reach)));
  const int j0 = std::max(0, static_cast<int>(std::floor(rel.y() - reach)));
  const int j1 = std::min(ny_ - 1, static_cast<int>(std::floor(rel.y() + reach)));
  for (int j = j0; j <= j1; ++j) {
    const std::size_t row = static_cast<std::size_t>(j) * nx_;
    f(cellStart_[row + i0], cellStart_[row + i1 + 1]);
  }
}

template <typename F>
void NeighbourGrid::visitCells(const Vecf<2>& x, float radius, F&& f) const {
  forEachSlotRowNear(x, radius, [&](std::uint32_t first, std::uint32_t last) {
    for (std::uint32_t k = first; k < last; ++k) f(k);
  });
}

template <typename F>
void NeighbourGrid::forEachCellInRows(int row0, int row1, F&& f) const {
  const std::uint32_t* start = cellStart_.data();
  for (int cy = row0; cy < row1; ++cy) {
    const int ry0 = std::max(cy - 1, 0), ry1 = std::min(cy + 1, ny_ - 1);
    for (int cx = 0; cx < nx_; ++cx) {
      const std::size_t c = static_cast<std::size_t>(cy) * nx_ + cx;
      const std::uint32_t first = start[c], last = start[c + 1];
      if (first == last) continue;
      const int rx0 = std::max(cx - 1, 0), rx1 = std::min(cx + 1, nx_ - 1);
      Stencil st;
      st.cell = c;
      st.x0 = rx0;
      st.x1 = rx1;
      st.y0 = ry0;
      st.y1 = ry1;
      for (int ry = ry0; ry <= ry1; ++ry, ++st.count) {
        const std::size_t row = static_cast<std::size_t>(ry) * nx_;
        st.lo[st.count] = start[row + rx0];
        st.hi[st.count] = start[row + rx1 + 1];
      }
      f(first, last, st);
    }
  }
}

template <typename F>
void NeighbourGrid::forEachWithin(const Vecf<2>& x, float radius, F&& f) const {
  const float r2 = radius * radius;
  visitCells(x, radius, [&](std::uint32_t k) {
    if ((sorted_[k] - x).squaredNorm() < r2) f(static_cast<std::size_t>(order_[k]));
  });
}

template <typename F>
void NeighbourGrid::forEachNeighbour(std::size_t i, float radius, F&& f) const {
  const Vecf<2> x = points_[i];
  const float r2 = radius * radius;
  visitCells(x, radius, [&](std::uint32_t k) {
    const std::uint32_t j = order_[k];
    if (j != i && (sorted_[k] - x).squaredNorm() < r2) f(static_cast<std::size_t>(j));
  });
}

}  // namespace msim::crowd
