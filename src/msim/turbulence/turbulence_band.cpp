#include "msim/turbulence/turbulence_band.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <stdexcept>
#include <utility>

#include "msim/core/parallel.hpp"

namespace msim::turbulence {

template <int D>
TurbulenceBand<D>::TurbulenceBand(const GridSpec<D>& coarse, int refinement) : coarse_(coarse), refinement_(refinement) {
  if (refinement < 1) throw std::invalid_argument("TurbulenceBand: the refinement must be >= 1");
}

template <int D>
void TurbulenceBand<D>::mark(const std::vector<std::uint8_t>& seeds, const MacGrid<D>& velocity, double dt) {
  // Each coarse cell's distance (in cells, the maximum over the axes) to the seeds, by one pass
  // per axis: d_a(c) = min_k max(|k|, d_(a-1)(c + k e_a)), counted up to `far`.
  // The core lies within `reach` of them, the taper kTaper cells beyond.
  const double fastest = maxFaceSpeed(velocity);
  constexpr int kTaper = 2;
  const int reach = std::min(200, 1 + static_cast<int>(std::ceil(fastest * dt / coarse_.dx)));
  const int far = reach + kTaper;
  std::size_t cells = 1;
  std::array<std::ptrdiff_t, D> strides{};
  for (int d = 0; d < D; ++d) {
    strides[d] = static_cast<std::ptrdiff_t>(cells);
    cells *= static_cast<std::size_t>(coarse_.res[d]);
  }
  if (seeds.size() != cells) throw std::invalid_argument("TurbulenceBand::mark: one seed flag per coarse cell");
  level_.resize(cells);
  parallelFor(0, cells, [&](std::size_t i) { level_[i] = static_cast<std::uint8_t>(seeds[i] ? 0 : far + 1); }, 4096);
  std::vector<std::uint8_t>& next = scratch_;
  next.resize(cells);
  for (int a = 0; a < D; ++a) {
    parallelForCells<D>(coarse_.res, [&](const IVec<D>& c, std::size_t lin) {
      int level = level_[lin];
      for (int k = 1; k <= far && k < level; ++k)
        for (const int n : {c[a] - k, c[a] + k}) {
          if (n < 0 || n >= coarse_.res[a]) continue;
          const std::ptrdiff_t offset = static_cast<std::ptrdiff_t>(n - c[a]) * static_cast<std::ptrdiff_t>(strides[a]);
          level = std::min(level, std::max(k, int(level_[static_cast<std::size_t>(static_cast<std::ptrdiff_t>(lin) + offset)])));
        }
      next[lin] = static_cast<std::uint8_t>(level);
    });
    level_.swap(next);
  }
  // The core's bounding box, rounded out to whole blocks of kBoxBlock cells so the advection window
  // changes only every few steps as the marked cells spread.
  constexpr int kBoxBlock = 4;
  IVec<D> lo = coarse_.res, hi = IVec<D>::Zero();
  for (std::size_t i = 0; i < cells; ++i) {
    if (level_[i] > reach) continue;
    IVec<D> c;
    std::size_t rest = i;
    for (int d = 0; d < D; ++d) {
      c[d] = static_cast<int>(rest % static_cast<std::size_t>(coarse_.res[d]));
      rest /= static_cast<std::size_t>(coarse_.res[d]);
    }
    lo = lo.cwiseMin(c);
    hi = hi.cwiseMax(c + IVec<D>::Ones());
  }
  lo_ = hi_ = IVec<D>::Zero();
  if ((hi.array() > lo.array()).all()) {
    for (int d = 0; d < D; ++d) {
      lo_[d] = lo[d] / kBoxBlock * kBoxBlock;
      hi_[d] = std::min(coarse_.res[d], (hi[d] + kBoxBlock - 1) / kBoxBlock * kBoxBlock);
    }
  }
  // The weight at the coarse nodes: 1 at the corners of core cells, falling by 1 / kTaper per cell
  // beyond; at the fine nodes, interpolated multilinearly from them.
  const IVec<D> coarseNodes = coarse_.res + IVec<D>::Ones();
  std::size_t coarseNodeCount = 1;
  for (int d = 0; d < D; ++d) coarseNodeCount *= static_cast<std::size_t>(coarseNodes[d]);
  coarseNodeWeight_.resize(coarseNodeCount);
  parallelForCells<D>(coarseNodes, [&](const IVec<D>& node, std::size_t n) {
    int level = far + 1;
    for (int corner = 0; corner < (1 << D); ++corner) {
      IVec<D> c = node;
      bool inside = true;
      for (int d = 0; d < D; ++d) {
        c[d] -= (corner >> d) & 1;
        inside = inside && c[d] >= 0 && c[d] < coarse_.res[d];
      }
      if (!inside) continue;
      std::size_t lin = 0;
      for (int d = 0; d < D; ++d) lin += static_cast<std::size_t>(c[d]) * static_cast<std::size_t>(strides[d]);
      level = std::min(level, int(level_[lin]));
    }
    coarseNodeWeight_[n] = std::clamp(1.0f - static_cast<float>(level - reach) / kTaper, 0.0f, 1.0f);
  });
  const IVec<D> nodes = coarse_.res * refinement_ + IVec<D>::Ones();
  std::size_t nodeCount = 1, rows = 1;
  for (int d = 0; d < D; ++d) nodeCount *= static_cast<std::size_t>(nodes[d]);
  for (int d = 1; d < D; ++d) rows *= static_cast<std::size_t>(nodes[d]);
  nodeWeight_.resize(nodeCount);
  const int r = refinement_;
  const float invR = 1.0f / static_cast<float>(r);
  auto tap = [&](int fineIndex, int coarseCount) {  // coarse node below, its fraction; the stride is the caller's
    const int below = std::min(fineIndex / r, coarseCount - 2);
    return std::pair<int, float>(below, static_cast<float>(fineIndex - below * r) * invR);
  };
  const double marked = parallelSum(rows, [&](std::size_t row) {
    // The coarse node rows bracketing this fine row, blended across the other axes.
    thread_local std::vector<float> blended;
    blended.assign(static_cast<std::size_t>(coarseNodes[0]), 0.0f);
    std::array<std::pair<int, float>, D> across{};
    std::size_t rest = row;
    for (int d = 1; d < D; ++d) {
      across[d] = tap(static_cast<int>(rest % static_cast<std::size_t>(nodes[d])), coarseNodes[d]);
      rest /= static_cast<std::size_t>(nodes[d]);
    }
    bool any = false;
    for (int corner = 0; corner < (1 << (D - 1)); ++corner) {
      float w = 1.0f;
      std::size_t offset = 0, stride = static_cast<std::size_t>(coarseNodes[0]);
      for (int d = 1; d < D; ++d) {
        const bool up = (corner >> (d - 1)) & 1;
        w *= up ? across[d].second : 1.0f - across[d].second;
        offset += static_cast<std::size_t>(across[d].first + up) * stride;
        stride *= static_cast<std::size_t>(coarseNodes[d]);
      }
      if (w == 0.0f) continue;
      const float* source = coarseNodeWeight_.data() + offset;
      for (int x = 0; x < coarseNodes[0]; ++x) {
        blended[static_cast<std::size_t>(x)] += w * source[x];
        any = any || source[x] > 0.0f;
      }
    }
    float* weight = nodeWeight_.data() + row * static_cast<std::size_t>(nodes[0]);
    if (!any) {
      std::fill(weight, weight + nodes[0], 0.0f);
      return 0.0;
    }
    int count = 0;
    for (int x = 0; x < nodes[0]; ++x) {
      const auto [below, f] = tap(x, coarseNodes[0]);
      weight[x] = blended[static_cast<std::size_t>(below)] + f * (blended[static_cast<std::size_t>(below) + 1] - blended[static_cast<std::size_t>(below)]);
      count += weight[x] > 0.0f;
    }
    return double(count);
  });
  fraction_ = marked / static_cast<double>(nodeCount);
}

template class TurbulenceBand<2>;
template class TurbulenceBand<3>;

}  // namespace msim::turbulence
