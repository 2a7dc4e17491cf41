#include "msim/fluid/vortex/vortex_stretching.hpp"

#include "msim/core/parallel.hpp"

namespace msim::fluid {

Eigen::Vector3d stretchAndRescale(const Eigen::Vector3d& omega, const Eigen::Matrix3d& gradient, double dt) {
  const double magnitude = omega.norm();
  const Eigen::Vector3d stretched = omega + dt * (gradient * omega);  // (omega . grad) u = G omega
  const double stretchedMagnitude = stretched.norm();
  if (!(stretchedMagnitude > 0.0)) return omega;
  return stretched * (magnitude / stretchedMagnitude);
}

template <int D>
void stretchVortexParticles(VortexParticles<D>& particles, const MacGrid<D>& velocity, double dt) {
  requireValidVortexTimestep(dt, "stretchVortexParticles");
  if constexpr (D == 3) {
    const auto& x = particles.positions();
    auto& omega = particles.vorticities();
    parallelFor(0, x.size(), [&](std::size_t p) {
      omega[p] = stretchAndRescale(omega[p], velocityGradientAt<3>(velocity, x[p].template cast<double>()), dt);
    }, 256);
  }
}

template void stretchVortexParticles<2>(VortexParticles<2>&, const MacGrid<2>&, double);
template void stretchVortexParticles<3>(VortexParticles<3>&, const MacGrid<3>&, double);

}  // namespace msim::fluid
