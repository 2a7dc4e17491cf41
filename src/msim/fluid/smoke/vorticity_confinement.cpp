#include "msim/fluid/smoke/vorticity_confinement.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "msim/core/parallel.hpp"

namespace msim::fluid {

namespace {

// Central difference of f along `axis` at cell c, one-sided at the border.
template <typename T, int D, typename Get>
auto centralDifference(const Grid<T, D>& g, const IVec<D>& c, int axis, double dx, Get get) {
  IVec<D> lo = c, hi = c;
  if (c[axis] > 0) lo[axis] -= 1;
  if (c[axis] + 1 < g.size()[axis]) hi[axis] += 1;
  const double span = (hi[axis] - lo[axis]) * dx;
  return span > 0.0 ? (get(g(hi)) - get(g(lo))) / span : decltype((get(g(hi)) - get(g(lo))) / span){};
}

// Velocity at cell centres: the mean of the two faces of each axis.
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

}  // namespace

template <int D>
void computeVorticity(const MacGrid<D>& velocity, Vorticity<D>& vorticity) {
  Grid<Vecf<D>, D> centre(velocity.spec());
  centreVelocities<D>(velocity, centre);
  vorticityFromCentres<D>(centre, vorticity);
}

template <int D>
VorticityConfinement<D>::VorticityConfinement(const GridSpec<D>& spec)
    : centre_(spec), vorticity_(spec), magnitude_(spec), force_(spec) {}

template <int D>
void VorticityConfinement<D>::apply(MacGrid<D>& velocity, double epsilon, double dt, const Grid<float, D>* solid) {
  const GridSpec<D>& spec = velocity.spec();
  centreVelocities<D>(velocity, centre_);
  vorticityFromCentres<D>(centre_, vorticity_);
  parallelFor(0, magnitude_.count(), [&](std::size_t i) { magnitude_[i] = vorticity_[i].norm(); });

  const double dx = spec.dx;
  parallelForCells(force_, [&](const IVec<D>& c, std::size_t lin) {
    Vec<D> gradient;
    for (int a = 0; a < D; ++a)
      gradient[a] = centralDifference(magnitude_, c, a, dx, [](float m) { return static_cast<double>(m); });
    const double g = gradient.norm();
    // Where |omega| is flat there is no concentration to confine (and N is undefined).
    if (!(g > 1e-12 / dx)) {
      force_[lin] = Vecf<D>::Zero();
      return;
    }
    const Vec<D> N = gradient / g;
    const auto& w = vorticity_[lin];
    Vec<D> f;
    if constexpr (D == 2) {
      f = Vec<D>(N[1] * w[0], -N[0] * w[0]);  // N x (omega e_z)
    } else {
      f = N.cross(w.template cast<double>());
    }
    force_[lin] = (epsilon * dx * f).template cast<float>();
  });

  const float h = static_cast<float>(dt);
  for (int a = 0; a < D; ++a) {
    auto& u = velocity.component(a);
    parallelForCells(u, [&](const IVec<D>& f, std::size_t lin) {
      if (f[a] == 0 || f[a] == spec.res[a]) return;  // domain walls: the projection owns them
      IVec<D> left = f;
      left[a] -= 1;
      if (solid && ((*solid)(left) > 0.5f || (*solid)(f) > 0.5f)) return;
      u[lin] += h * 0.5f * (force_(left)[a] + force_(f)[a]);
    });
  }
}

template void computeVorticity<2>(const MacGrid<2>&, Vorticity<2>&);
template void computeVorticity<3>(const MacGrid<3>&, Vorticity<3>&);
template class VorticityConfinement<2>;
template class VorticityConfinement<3>;

}  // namespace msim::fluid
