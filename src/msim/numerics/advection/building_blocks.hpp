#pragma once
// One first-order upwind step over every sample of a field (Selle eq. 2.3): the building block
// that BFECC and MacCormack call forwards (velocity V) and backwards (velocity -V). The
// semi-Lagrangian block lives in semi_lagrangian.hpp.
//
// Alongside the new values it can report, per sample, the range of the old samples the step read
// (for the extrema limiter of ch. 2.7) and whether any of them was solid (for the first-order
// reversion near solids of ch. 2.9). Solid samples are copied unchanged.
#include <cstdint>

#include "msim/core/grid.hpp"
#include "msim/numerics/advection/field_layout.hpp"
#include "msim/numerics/advection/velocity_sampler.hpp"

namespace msim::numerics {

template <typename T>
struct StepOutputs {
  T* lo = nullptr;                 // per sample: min of the samples read (optional)
  T* hi = nullptr;                 // per sample: max of the samples read (optional)
  std::uint8_t* touched = nullptr;  // per sample: OR-ed with "read a solid sample" (optional)
};

// dst = one upwind step of src over dt. `solid` (optional) flags solid samples.
template <typename T, int D>
void upwindStep(const FieldLayout<D>& layout, const Grid<T, D>& src, Grid<T, D>& dst,
                const VelocitySampler<D>& velocity, double dt, const std::uint8_t* solid, const StepOutputs<T>& out);

}  // namespace msim::numerics
