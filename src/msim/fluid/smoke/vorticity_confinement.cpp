#include "msim/fluid/smoke/vorticity_confinement.hpp"

#include <cmath>

#include <Eigen/Geometry>

#include "msim/core/parallel.hpp"

namespace msim::fluid {

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

template class VorticityConfinement<2>;
template class VorticityConfinement<3>;

}  // namespace msim::fluid
