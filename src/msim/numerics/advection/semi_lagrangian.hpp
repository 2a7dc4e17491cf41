#pragma once
// The semi-Lagrangian building block (Selle ch. 2.3) split in two phases: trace the characteristic
// foot of every sample (`traceFeet`), then interpolate a field at those feet (`sampleAtFeet`).
// The split matters for speed: MacCormack and BFECC run the block forwards and backwards in the
// same velocity, and every scalar advected by one velocity and dt has the same feet, so the costly
// part (with RK2, 3 velocity samples per field sample) runs once per velocity instead of once per
// step and per field. A foot is stored as its interpolation stencil, so a step is a single gather pass.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advection_settings.hpp"
#include "msim/numerics/advection/field_layout.hpp"

namespace msim::numerics {

// D-linear interpolation stencils, one per sample of a field, as structure of arrays (the
// interpolation pass loads them as vectors).
template <typename T, int D>
struct Feet {
  std::vector<std::int32_t> base;  // linear index of the lower corner (fields hold < 2^31 samples)
  std::vector<std::uint8_t> wrap;  // bit a set: the upper corner along axis a is sample 0 (periodic wrap)
  std::vector<T> t[D];             // weights of the upper corners

  void resize(std::size_t n) {
    base.resize(n);
    wrap.resize(n);
    for (auto& w : t) w.resize(n);
  }
};

// The corner addressing of one field layout (clamped or periodic axes, single-sample axes) for
// the stencils of FieldLayout::stencil, computed in sample space (see semi_lagrangian.cpp).
template <int D>
struct SampleLattice {
  int size[D];
  int period[D];
  bool periodic[D];
  int first[D];       // global index of sample 0 (FieldLayout::first)
  int globalSize[D];  // global samples per axis: clamping happens at the global border
  std::ptrdiff_t stride[D];
  std::ptrdiff_t step[D];      // lower -> upper corner: stride, 0 on single-sample axes
  std::ptrdiff_t wrapStep[D];  // lower -> upper corner when it wraps: from the last sample to 0

  SampleLattice() = default;
  explicit SampleLattice(const FieldLayout<D>& layout) {
    for (int a = 0; a < D; ++a) {
      size[a] = layout.size[a];
      period[a] = layout.period[a];
      periodic[a] = layout.periodic[a];
      first[a] = layout.first[a];
      globalSize[a] = layout.globalSize[a];
      stride[a] = layout.stride[a];
      step[a] = size[a] < 2 ? 0 : stride[a];
      wrapStep[a] = -static_cast<std::ptrdiff_t>(size[a] - 1) * stride[a];
    }
  }
};

// The feet of the forward (velocity V) and backward (velocity -V) steps of every sample of
// `field`, in `velocity` over dt. Both grids lie at `placement` in the global domain (the
// default: they are the domain); positions are traced in global sample coordinates. Solid samples (solid[i] != 0) get their own position
// as both feet, so interpolating there returns the old value unchanged. If `touched` is given,
// touched[i] = any corner of either stencil of sample i is solid (Selle ch. 2.9).
template <typename T, int D>
void traceFeet(const Grid<T, D>& field, const AxisBoundaries<D>& boundaries, const MacGrid<D>& velocity, double dt,
               BackTrace trace, const std::uint8_t* solid, Feet<T, D>& forward, Feet<T, D>& backward,
               std::uint8_t* touched, const BlockPlacement<D>& placement = {});

// dst[i] = src interpolated at feet[i]; lo/hi (optional) get the range of the corners read.
template <typename T, int D>
void sampleAtFeet(const SampleLattice<D>& lattice, const Feet<T, D>& feet, const T* src, T* dst, T* lo,
                  T* hi);

}  // namespace msim::numerics
