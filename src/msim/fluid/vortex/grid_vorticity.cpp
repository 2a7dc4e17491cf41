#include "msim/fluid/vortex/grid_vorticity.hpp"

#include "msim/core/parallel.hpp"

namespace msim::fluid {

template <int D>
void centreVelocities(const MacGrid<D>& u, Grid<Vecf<D>, D>& centre) {
  parallelForCells(centre, [&](const IVec<D>& c, std::size_t lin) {
    Vecf<D> v;
    for (int a = 0; a < D; ++a) {
      const auto& face = u.component(a);
      const std::size_t lower = face.index(c);
      v[a] = 0.5f * (face[lower] + face[lower + face.stride(a)]);
    }
    centre[lin] = v;
  });
}

template <int D>
void vorticityFromCentres(const Grid<Vecf<D>, D>& centre, Vorticity<D>& vorticity) {
  const double dx = centre.spec().dx;
  parallelForCells(vorticity, [&](const IVec<D>& c, std::size_t lin) {
    // d(u_component)/d(x_axis) by central differences of the centre velocities.
    auto d = [&](int component, int axis) {
      return centralDifference(centre, c, axis, dx, [component](const Vecf<D>& v) { return static_cast<double>(v[component]); });
    };
    auto& w = vorticity[lin];
    if constexpr (D == 2) {
      w[0] = static_cast<float>(d(1, 0) - d(0, 1));
    } else {
      w[0] = static_cast<float>(d(2, 1) - d(1, 2));
      w[1] = static_cast<float>(d(0, 2) - d(2, 0));
      w[2] = static_cast<float>(d(1, 0) - d(0, 1));
    }
  });
}

template <int D>
void computeVorticity(const MacGrid<D>& velocity, Vorticity<D>& vorticity) {
  Grid<Vecf<D>, D> centre(velocity.spec());
  centreVelocities<D>(velocity, centre);
  vorticityFromCentres<D>(centre, vorticity);
}

template void centreVelocities<2>(const MacGrid<2>&, Grid<Vecf<2>, 2>&);
template void centreVelocities<3>(const MacGrid<3>&, Grid<Vecf<3>, 3>&);
template void vorticityFromCentres<2>(const Grid<Vecf<2>, 2>&, Vorticity<2>&);
template void vorticityFromCentres<3>(const Grid<Vecf<3>, 3>&, Vorticity<3>&);
template void computeVorticity<2>(const MacGrid<2>&, Vorticity<2>&);
template void computeVorticity<3>(const MacGrid<3>&, Vorticity<3>&);

}  // namespace msim::fluid
