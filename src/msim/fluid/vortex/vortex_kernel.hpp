#pragma once
// The distribution kernel xi_p(x - x_p) of a vortex particle and the force it drives (Selle
// ch. 3.4.2 and 3.5). Shared by everything that puts vortex particles on a grid (smoke, liquids,
// and the velocity-vorticity domain decomposition of Golas ch. 2).
//
// A particle with vorticity omega_p defines the analytic vorticity  w_p(x) = xi_p(x - x_p) omega_p.
// For a rotationally symmetric kernel that decreases with distance, the confinement direction
// N = grad|w| / |grad|w|| is  N_p(x) = (x_p - x) / |x_p - x|  (towards the particle), and the
// force is the confinement force of that vorticity (ch. 3.4.2):
//   F_p(x) = eps_p (N_p x w_p(x)) = eps_p xi_p(|x - x_p|) (N_p x omega_p).
// It is azimuthal (F_p . (x - x_p) = 0), zero outside the support, and, being grad(H) x omega_p
// with H(|d|) = -integral of xi, divergence-free; it integrates to zero (it is odd in x - x_p).
// At x = x_p the direction N_p is undefined and F_p is set to 0 [seed notes A2, I].
//
// Kernels (d = |x - x_p|, r the particle's radius):
//   ClampedGaussian  xi = exp(-d^2 / 2r^2) / (r^3 (2 pi)^{3/2})  for d <= r, else 0 (ch. 3.5, used
//                    in Figs. 3.3-3.5). Implemented as printed: r is both the Gaussian's sigma and
//                    the cut-off, so only erf(1/sqrt2) - sqrt(2/pi) e^{-1/2} = 19.9% of the mass is
//                    inside the support, and xi jumps from e^{-1/2} xi(0) to 0 at d = r (F_p then
//                    has a tangential jump there: a thin vortex sheet of opposite sign that keeps
//                    the total vorticity unchanged). In 2D: exp(-d^2 / 2r^2) / (2 pi r^2) [I],
//                    39.3% of the mass inside.
//   Tent             xi = (1 - d/r) 3 / (pi r^3) for d <= r (3/(pi r^2) in 2D): the kernel ILM used
//                    (ch. 3.5; no formula given, normalised here to unit mass [I]); continuous, so
//                    its force has no sheet at the cut-off.
// Units: xi is 1/m^D. The seed gives no eps_p and no units, so eps_p |omega_p| is one tuned
// strength; F_p is an acceleration [m/s^2].
#include <cmath>
#include <numbers>
#include <string_view>

#include <Eigen/Geometry>

#include "msim/core/vec.hpp"

namespace msim::fluid {

enum class VortexKernel { ClampedGaussian, Tent };

inline std::string_view vortexKernelName(VortexKernel kernel) {
  return kernel == VortexKernel::Tent ? "tent" : "clamped_gaussian";
}

// A particle's vorticity: the full vector in 3D; in 2D only omega_z exists, stored as a 1-vector
// (the layout of fluid::Vorticity<D> on the grid). Double precision: the stretching's rescale keeps
// |omega_p| to 1e-12 relative, which a float could not hold.
template <int D>
using VortexVector = Eigen::Matrix<double, (D == 3 ? 3 : 1), 1>;

// The kernel's constant factor: xi(d) = normalisation * shape(d / r) with shape
// exp(-(d/r)^2 / 2) (ClampedGaussian) or 1 - d/r (Tent) for d <= r.
template <int D>
double vortexKernelNormalisation(VortexKernel kernel, double radius) {
  static_assert(D == 2 || D == 3);
  const double rD = D == 3 ? radius * radius * radius : radius * radius;
  if (kernel == VortexKernel::Tent) return 3.0 / (std::numbers::pi * rD);
  return 1.0 / (rD * (D == 3 ? std::pow(2.0 * std::numbers::pi, 1.5) : 2.0 * std::numbers::pi));
}

// xi(d) for a particle of radius r > 0 [1/m^D].
template <int D>
double vortexKernelValue(VortexKernel kernel, double distance, double radius) {
  if (!(distance <= radius)) return 0.0;
  const double shape = kernel == VortexKernel::Tent ? 1.0 - distance / radius
                                                    : std::exp(-distance * distance / (2.0 * radius * radius));
  return vortexKernelNormalisation<D>(kernel, radius) * shape;
}

// N x omega for a unit vector N: the cross product in 3D; in 2D N x (omega_z e_z) = omega_z (N_y, -N_x).
template <int D>
Vec<D> crossWithVorticity(const Vec<D>& n, const VortexVector<D>& omega) {
  if constexpr (D == 3)
    return n.cross(omega);
  else
    return Vec<D>(n[1] * omega[0], -n[0] * omega[0]);
}

// F_p at offset d = x - x_p from one particle (ch. 3.4.2): eps xi(|d|) (N_p x omega_p), with
// N_p = -d / |d|; 0 at d = 0 and beyond the radius.
template <int D>
Vec<D> vortexParticleForce(VortexKernel kernel, const Vec<D>& offset, const VortexVector<D>& omega, double radius,
                           double strength) {
  const double distance = offset.norm();
  const double xi = vortexKernelValue<D>(kernel, distance, radius);
  if (xi == 0.0 || distance == 0.0) return Vec<D>::Zero();
  const Vec<D> towardsParticle = -offset / distance;  // N_p
  return (strength * xi) * crossWithVorticity<D>(towardsParticle, omega);
}

}  // namespace msim::fluid
