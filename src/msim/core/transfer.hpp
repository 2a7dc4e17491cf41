#pragma once
// Particle <-> grid transfer with a separable kernel of compact support.
//
//   Linear           tent, 2 samples per axis: w(r) = 1 - |r| for |r| < 1
//   QuadraticBSpline 3 samples per axis: w(r) = 3/4 - r^2 (|r| < 1/2), (3/2 - |r|)^2 / 2 (|r| < 3/2)
//
// (r measured in samples). Both are partitions of unity with exact first moments, so a splat
// moves exactly the particle's value onto the grid and a gather reproduces linear fields exactly.
//
// Borders: a kernel tap that falls outside the grid is folded onto the nearest in-grid sample
// (index clamping), so a Sum splat conserves the total even for particles at or beyond the border.
// gather uses the same clamped taps, which makes it the exact transpose of a Sum splat:
//   sum_c splat(v)(c) g(c) == sum_p v_p gather(g)(p).
// gather is exact on linear fields wherever all taps are inside the grid (everywhere within the
// sample range for Linear; one half-sample further in for QuadraticBSpline).
//
// Splats are parallel and deterministic: particles are bucketed (stable counting sort) into slabs
// of kSlabWidth samples along the slowest grid axis, and the slabs are processed in two colours,
// even slabs in parallel and then odd ones. Slabs of one colour are kSlabWidth samples apart, wider
// than a stencil, so they never write the same sample, and within a slab particles are added in
// input order. Every sample therefore sums its contributions in the same order whatever the
// thread count, and the result is bitwise reproducible. Sums are accumulated in double.
#include <array>
#include <cstdint>
#include <span>
#include <type_traits>
#include <vector>

#include "msim/core/bucket_sort.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim {

enum class TransferKernel { Linear, QuadraticBSpline };

// Sum: target(c) += sum_p w_p(c) v_p (the grid content is kept and added to; fill(0) first for a
//      fresh deposit). Use it for conserved quantities (mass, density, momentum).
// Normalized: target(c) = sum_p w_p(c) v_p / sum_p w_p(c), or `emptyValue` where no particle has
//      weight on c. The grid content is replaced. Use it for intensive quantities (velocity).
enum class SplatMode { Sum, Normalized };

// Holds the bucketing and double accumulation buffers so repeated splats do not reallocate.
// Not thread-safe: one Splatter per concurrent caller (each splat is itself parallel).
template <int D>
class Splatter {
 public:
  static constexpr int kSlabWidth = 4;

  void splat(std::span<const Vecf<D>> positions, std::span<const float> values, Grid<float, D>& target,
             TransferKernel kernel, SplatMode mode = SplatMode::Sum, float emptyValue = 0.0f);

  // Component a of each value goes onto face grid a, weighted with that grid's own sample offset.
  void splat(std::span<const Vecf<D>> positions, std::span<const Vecf<D>> values, MacGrid<D>& target,
             TransferKernel kernel, SplatMode mode = SplatMode::Sum, float emptyValue = 0.0f);

  // N Sum splats onto grids of one layout in one pass: values[q] onto *targets[q]. One bucketing
  // and one stencil per particle serve all N (a transfer that splats several quantities pays for
  // them once); every sample adds its contributions in the same order and arithmetic as N
  // separate splat() calls, so the result is bitwise the same. std::invalid_argument if the grids'
  // layouts differ or a value span's length is not the number of positions. N = 2, 3.
  template <std::size_t N>
  void splatSums(std::span<const Vecf<D>> positions, const std::array<std::span<const float>, N>& values,
                 const std::array<Grid<float, D>*, N>& targets, TransferKernel kernel);

 private:
  // valueOf(p, q): particle p's value for target q.
  template <typename Kernel, std::size_t N, typename ValueOf>
  void splatWith(std::span<const Vecf<D>> positions, const ValueOf& valueOf,
                 const std::array<Grid<float, D>*, N>& targets, SplatMode mode, float emptyValue);
  template <typename Kernel>
  void bucketBySlab(std::span<const Vecf<D>> positions, const Grid<float, D>& target);

  std::vector<double> weightedSum_;  // sum of w*v per sample (N interleaved per sample)
  std::vector<double> weightSum_;    // sum of w per sample (Normalized only)
  BucketSort buckets_;  // particle indices grouped by slab, stable
};

// One-off splat with a temporary Splatter (allocates; keep a Splatter for repeated splats).
template <int D>
void splat(std::type_identity_t<std::span<const Vecf<D>>> positions, std::span<const float> values,
           Grid<float, D>& target, TransferKernel kernel, SplatMode mode = SplatMode::Sum, float emptyValue = 0.0f);
template <int D>
void splat(std::type_identity_t<std::span<const Vecf<D>>> positions,
           std::type_identity_t<std::span<const Vecf<D>>> values, MacGrid<D>& target, TransferKernel kernel,
           SplatMode mode = SplatMode::Sum, float emptyValue = 0.0f);

// out[p] = sum_c w_p(c) grid(c); out.size() must equal positions.size(). Parallel.
template <int D>
void gather(const Grid<float, D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions,
            TransferKernel kernel, std::span<float> out);
template <int D>
std::vector<float> gather(const Grid<float, D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions,
                          TransferKernel kernel);
// Vector gather from a MAC grid: component a from face grid a.
template <int D>
void gather(const MacGrid<D>& grid, std::type_identity_t<std::span<const Vecf<D>>> positions, TransferKernel kernel,
            std::type_identity_t<std::span<Vecf<D>>> out);
// Vector gathers from N MAC grids of one layout at the same positions, out[q] from *grids[q]: one
// stencil per position and component serves all N (bitwise what N separate gathers give).
// std::invalid_argument if the layouts differ or an output's length is not the number of positions.
// N = 2.
template <int D, std::size_t N>
void gather(const std::array<const MacGrid<D>*, N>& grids, std::type_identity_t<std::span<const Vecf<D>>> positions,
            TransferKernel kernel, const std::array<std::span<Vecf<D>>, N>& out);

}  // namespace msim
