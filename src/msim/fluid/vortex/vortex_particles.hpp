#pragma once
// VortexParticles<D>: the state of Selle's vortex particles (ch. 3.3-3.4), a structure of arrays:
// position x_p [m], vorticity omega_p [1/s] (VortexVector: 3 components in 3D, omega_z in 2D),
// kernel radius r_p [m] and strength eps_p (the confinement strength of ch. 3.4.2; see
// vortex_kernel.hpp for its units). Particle i is index i in every array.
//
// Not a core Particles<D> set: that stores float channels, and omega_p is kept in double so the
// rescale after stretching holds |omega_p| to 1e-12 (vortex_stretching.hpp).
//
// The operations of a step, in the order of the hybrid solver (seed notes A2):
//   advectVortexParticles   (vortex_advection.hpp)   x_p += dt u(x_p)
//   stretchVortexParticles  (vortex_stretching.hpp)  omega_p += dt (omega_p . grad) u, rescaled
//   addVortexForce          (vortex_force.hpp)       u += dt sum_p F_p on the MAC faces
//   seedVortexParticles / VortexEmitter (vortex_seeding.hpp), removeVortexParticlesInSolid /
//   pushVortexParticlesOutOfSolid (vortex_solids.hpp).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/fluid/vortex/vortex_kernel.hpp"

namespace msim::fluid {

template <int D>
class VortexParticles {
 public:
  // Appends a particle and returns its index. std::invalid_argument (naming the value) for a
  // non-finite position or vorticity, a radius that is not > 0, or a strength that is negative or
  // not finite.
  std::size_t add(const Vec<D>& position, const VortexVector<D>& vorticity, double radius, double strength);

  std::size_t size() const { return positions_.size(); }
  bool empty() const { return positions_.empty(); }
  void reserve(std::size_t n);
  void clear();

  // Direct access for the step functions. Writing through them skips add()'s checks.
  std::vector<Vecf<D>>& positions() { return positions_; }
  const std::vector<Vecf<D>>& positions() const { return positions_; }
  std::vector<VortexVector<D>>& vorticities() { return vorticities_; }
  const std::vector<VortexVector<D>>& vorticities() const { return vorticities_; }
  const std::vector<double>& radii() const { return radii_; }
  const std::vector<double>& strengths() const { return strengths_; }
  // Largest radius (0 when empty): how far any particle's force reaches.
  double maxRadius() const;

  // Removes every particle i with remove(i) true, survivors keeping their order; the predicate
  // sees the set as it was before any removal. Returns how many were removed.
  template <typename Predicate>
  std::size_t removeIf(Predicate&& remove) {
    const std::size_t n = size();
    std::size_t kept = 0;
    for (std::size_t i = 0; i < n; ++i) {
      if (remove(i)) continue;
      if (kept != i) {
        positions_[kept] = positions_[i];
        vorticities_[kept] = vorticities_[i];
        radii_[kept] = radii_[i];
        strengths_[kept] = strengths_[i];
      }
      ++kept;
    }
    positions_.resize(kept);
    vorticities_.resize(kept);
    radii_.resize(kept);
    strengths_.resize(kept);
    return n - kept;
  }

 private:
  std::vector<Vecf<D>> positions_;
  std::vector<VortexVector<D>> vorticities_;
  std::vector<double> radii_;
  std::vector<double> strengths_;
};

// std::invalid_argument unless radius > 0 and strength >= 0 (both finite); `what` names the
// quantity in the message (e.g. a scene key).
void requireValidVortexRadius(double radius, const char* what);
void requireValidVortexStrength(double strength, const char* what);
// std::invalid_argument unless dt is finite and >= 0; `where` names the caller.
void requireValidVortexTimestep(double dt, const char* where);

}  // namespace msim::fluid
