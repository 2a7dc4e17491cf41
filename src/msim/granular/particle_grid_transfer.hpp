#pragma once
// Particle <-> grid transfers of the granular FLIP scheme (Narain 2011 ch. 5.4, seed lines
// 1378-1382): at the start of a step every particle is a point mass split among its 8 neighbouring
// samples with trilinear weights (core/transfer.hpp, Linear kernel, Sum splats: mass and momentum
// are conserved to round-off); after the continuum solve the particle velocities take the change
// of the grid velocity (FLIP, Brackbill and Ruppel 1986; Zhu and Bridson 2005).
#include <array>
#include <span>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/transfer.hpp"
#include "msim/granular/granular_particles.hpp"

namespace msim::granular {

// What the continuum solver reads from the particles, on one GridSpec.
struct ParticleGridFields {
  ParticleGridFields() = default;
  explicit ParticleGridFields(const GridSpec<3>& spec);

  // Cell-centred.
  Grid<float, 3> mass;      // [kg]
  Grid<float, 3> volume;    // sum of w m_i / rho_max_i [m^3]: the volume the material would fill
                            // fully packed, so phi = volume / cellVolume (ch. 5.5.2)
  Grid<float, 3> friction;  // volume-weighted alpha: sum w V_i alpha_i / sum w V_i, 0 where empty
  // Faces (component a on the faces normal to axis a).
  MacGrid<3> momentum;    // [kg m/s]
  MacGrid<3> faceMass;    // [kg]
  MacGrid<3> faceVolume;  // [m^3], as `volume`
  MacGrid<3> velocity;    // momentum / faceMass, 0 where a face has no mass [m/s]
};

// Pure FLIP (1) keeps the particles' velocity detail but lets noise that the grid cannot see grow;
// pure PIC (0) re-averages the velocities through the grid every step, which damps the flow
// visibly. A small PIC share removes the noise at little dissipation (Zhu and Bridson 2005 use
// the same 0.95 blend).
inline constexpr double kDefaultFlipRatio = 0.95;

// Holds the splat buffers and per-particle scratch so repeated transfers do not allocate.
// Not thread-safe; each transfer is parallel and deterministic.
class ParticleGridTransfer {
 public:
  // Fills every field of `out` (its layout decides the grid). std::invalid_argument for a particle
  // whose material index is outside `materials`.
  void toGrid(const GranularParticles& particles, std::span<const GranularMaterial> materials, ParticleGridFields& out);

  // FLIP/PIC update: v_p <- flipRatio (v_p + I(newVelocity - oldVelocity)) + (1 - flipRatio) I(newVelocity),
  // I the trilinear interpolation at x_p (core gather). flipRatio in [0, 1].
  void toParticles(const MacGrid<3>& oldVelocity, const MacGrid<3>& newVelocity, GranularParticles& particles,
                   double flipRatio = kDefaultFlipRatio);

 private:
  Splatter<3> splatter_;
  // Per particle: m / rho_max, that times alpha, and the components of m v.
  std::vector<float> volume_, volumeFriction_;
  std::array<std::vector<float>, 3> momentum_;
  std::vector<Vecf<3>> oldAt_, newAt_;  // per particle: gathered grid velocities
};

}  // namespace msim::granular
