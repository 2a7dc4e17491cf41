#include "msim/crowd/neighbour_grid.hpp"

#include <limits>
#include <stdexcept>

#include <tbb/blocked_range.h>
#include <tbb/parallel_for.h>
#include <tbb/parallel_reduce.h>
#include <tbb/task_arena.h>

namespace msim::crowd {

namespace {

struct Bounds {
  Vecf<2> lo = Vecf<2>::Constant(std::numeric_limits<float>::max());
  Vecf<2> hi = Vecf<2>::Constant(std::numeric_limits<float>::lowest());
};

// Points per counting block: below this a block's histogram costs more than it saves.
constexpr std::size_t kBlockPoints = 1 << 14;
constexpr std::size_t kMaxBlocks = 8;
// Spans of cells the offset scan runs in parallel over.
constexpr std::size_t kScanSpans = 64;

}  // namespace

void NeighbourGrid::build(std::span<const Vecf<2>> points, float cellSize) {
  if (!(cellSize > 0.0f)) throw std::invalid_argument("NeighbourGrid::build: cellSize must be > 0");
  if (points.size() >= std::numeric_limits<std::uint32_t>::max())
    throw std::invalid_argument("NeighbourGrid::build: too many points for 32-bit indices");
  const std::size_t n = points.size();
  points_.assign(points.begin(), points.end());  // reuses capacity on rebuilds
  cellOf_.resize(n);
  order_.resize(n);
  sorted_.resize(n);
  if (n == 0) {
    nx_ = ny_ = 0;
    cellSize_ = cellSize;
    cellStart_.assign(1, 0);
    return;
  }

  const Bounds b = tbb::parallel_reduce(
      tbb::blocked_range<std::size_t>(0, n, 1 << 14), Bounds{},
      [&](const tbb::blocked_range<std::size_t>& r, Bounds acc) {
        for (std::size_t i = r.begin(); i != r.end(); ++i) {
          acc.lo = acc.lo.cwiseMin(points[i]);
          acc.hi = acc.hi.cwiseMax(points[i]);
        }
        return acc;
      },
      [](Bounds a, const Bounds& c) {
        a.lo = a.lo.cwiseMin(c.lo);
        a.hi = a.hi.cwiseMax(c.hi);
        return a;
      });

  // A few sparse points spread far apart must not allocate a huge grid: cap the cell count at a
  // small multiple of the point count by enlarging the cells (queries stay exact, just visit more).
  origin_ = b.lo;
  const Vecf<2> extent = b.hi - b.lo;
  const double maxCells = 4.0 * static_cast<double>(n) + 64.0;
  float cs = cellSize;
  auto cellsFor = [&](float c) {
    return (std::floor(extent.x() / c) + 1.0) * (std::floor(extent.y() / c) + 1.0);
  };
  while (cellsFor(cs) > maxCells) cs *= 1.5f;
  cellSize_ = cs;
  nx_ = static_cast<int>(std::floor(extent.x() / cs)) + 1;
  ny_ = static_cast<int>(std::floor(extent.y() / cs)) + 1;
  const std::size_t cells = static_cast<std::size_t>(nx_) * ny_;

  // Stable counting sort in blocks: each block finds and counts the cells of its own points, an
  // exclusive scan over (cell, block) turns the counts into write offsets, each block scatters its
  // points. A stable sort has a unique result, so the order does not depend on the block or thread
  // count. One block per thread at most: every block adds a cell-count row to zero and to scan.
  const std::size_t threads = static_cast<std::size_t>(tbb::this_task_arena::max_concurrency());
  const std::size_t blocks = std::clamp<std::size_t>(n / kBlockPoints, 1, std::min(kMaxBlocks, threads));
  const std::size_t per = (n + blocks - 1) / blocks;
  blockCount_.resize(blocks * cells);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t blk) {
    std::uint32_t* count = blockCount_.data() + blk * cells;
    std::fill(count, count + cells, 0u);
    const std::size_t end = std::min(n, (blk + 1) * per);
    // Same cell formula as visitCells, so a query sees exactly the cell a point was put in.
    const Vecf<2> origin = origin_;
    const float size = cellSize_;
    const int lastX = nx_ - 1, lastY = ny_ - 1, rowLength = nx_;
    for (std::size_t i = blk * per; i < end; ++i) {
      const Vecf<2> rel = (points[i] - origin) / size;
      const int cx = std::clamp(static_cast<int>(std::floor(rel.x())), 0, lastX);
      const int cy = std::clamp(static_cast<int>(std::floor(rel.y())), 0, lastY);
      const std::uint32_t c = static_cast<std::uint32_t>(cy) * rowLength + cx;
      cellOf_[i] = c;
      ++count[c];
    }
  });
  // The exclusive scan over (cell, block), cell major, in parallel over spans of cells: the span
  // totals first, then each span from its offset.
  cellStart_.resize(cells + 1);
  const std::size_t spans = std::min<std::size_t>(cells, kScanSpans), perSpan = (cells + spans - 1) / spans;
  spanTotal_.assign(spans + 1, 0u);
  tbb::parallel_for(std::size_t(0), spans, [&](std::size_t sp) {
    std::uint32_t total = 0;
    for (std::size_t c = sp * perSpan; c < std::min(cells, (sp + 1) * perSpan); ++c)
      for (std::size_t blk = 0; blk < blocks; ++blk) total += blockCount_[blk * cells + c];
    spanTotal_[sp + 1] = total;
  });
  for (std::size_t sp = 0; sp < spans; ++sp) spanTotal_[sp + 1] += spanTotal_[sp];
  tbb::parallel_for(std::size_t(0), spans, [&](std::size_t sp) {
    std::uint32_t running = spanTotal_[sp];
    for (std::size_t c = sp * perSpan; c < std::min(cells, (sp + 1) * perSpan); ++c) {
      cellStart_[c] = running;
      for (std::size_t blk = 0; blk < blocks; ++blk) {
        std::uint32_t& slot = blockCount_[blk * cells + c];
        const std::uint32_t k = slot;
        slot = running;
        running += k;
      }
    }
  });
  cellStart_[cells] = static_cast<std::uint32_t>(n);
  tbb::parallel_for(std::size_t(0), blocks, [&](std::size_t blk) {
    std::uint32_t* offset = blockCount_.data() + blk * cells;
    const std::size_t end = std::min(n, (blk + 1) * per);
    for (std::size_t i = blk * per; i < end; ++i) {
      const std::uint32_t k = offset[cellOf_[i]]++;
      order_[k] = static_cast<std::uint32_t>(i);
      sorted_[k] = points_[i];
    }
  });
}

}  // namespace msim::crowd
