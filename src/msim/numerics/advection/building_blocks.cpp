#include "msim/numerics/advection/building_blocks.hpp"

#include <algorithm>
#include <cmath>
#include <limits>

#include "msim/core/parallel.hpp"

namespace msim::numerics {

namespace {

// Range and solid contact of the samples one step read.
struct ReadSet {
  double lo = std::numeric_limits<double>::infinity();
  double hi = -std::numeric_limits<double>::infinity();
  bool solid = false;
  void add(double v, bool isSolid) {
    lo = std::min(lo, v);
    hi = std::max(hi, v);
    solid = solid || isSolid;
  }
};

// Eq. 2.3 per axis, written with the upwind neighbour on the side the flow comes from (the
// printed eq. 2.3 has the two cases swapped; ch. 2.6 uses u_i - u_{i-1} for a > 0):
//   phi_i^{n+1} = phi_i - dt/dx sum_a u_a (phi_i - phi_{i-e_a})   for u_a > 0, mirrored for u_a < 0.
template <typename T, int D>
double upwind(const FieldLayout<D>& layout, const T* src, const IVec<D>& c, std::size_t lin, const Vec<D>& u,
              double dt, const std::uint8_t* solid, ReadSet& read) {
  const double centre = src[lin];
  read.add(centre, false);
  double change = 0.0;
  for (int a = 0; a < D; ++a) {
    if (u[a] == 0.0) continue;
    const int delta = u[a] > 0.0 ? -1 : 1;
    const std::size_t j = lin + (layout.neighbour(a, c[a], delta) - c[a]) * layout.stride[a];
    const double upstream = src[j];
    change += std::abs(u[a]) * (centre - upstream);
    read.add(upstream, solid && solid[j]);
  }
  return centre - dt / layout.dx * change;
}

}  // namespace

template <typename T, int D>
void upwindStep(const FieldLayout<D>& layout, const Grid<T, D>& src, Grid<T, D>& dst,
                const VelocitySampler<D>& velocity, double dt, const std::uint8_t* solid, const StepOutputs<T>& out) {
  const T* in = src.data().data();
  T* result = dst.data().data();
  parallelForCells<D>(layout.size, [&](const IVec<D>& c, std::size_t lin) {
    if (solid && solid[lin]) {
      result[lin] = in[lin];
      if (out.lo) out.lo[lin] = out.hi[lin] = in[lin];
      return;
    }
    ReadSet read;
    const double v = upwind(layout, in, c, lin, velocity(layout.position(c)), dt, solid, read);
    result[lin] = static_cast<T>(v);
    if (out.lo) {
      out.lo[lin] = static_cast<T>(read.lo);
      out.hi[lin] = static_cast<T>(read.hi);
    }
    if (out.touched) out.touched[lin] |= static_cast<std::uint8_t>(read.solid);
  });
}

#define MSIM_INSTANTIATE(T, D)                                                                                   \
  template void upwindStep<T, D>(const FieldLayout<D>&, const Grid<T, D>&, Grid<T, D>&, const VelocitySampler<D>&, \
                                 double, const std::uint8_t*, const StepOutputs<T>&);
MSIM_INSTANTIATE(float, 2)
MSIM_INSTANTIATE(float, 3)
MSIM_INSTANTIATE(double, 2)
MSIM_INSTANTIATE(double, 3)
#undef MSIM_INSTANTIATE

}  // namespace msim::numerics
