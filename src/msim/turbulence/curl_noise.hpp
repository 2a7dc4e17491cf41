#pragma once
// Curl noise (Narain 2011 ch. 3.5, after Bridson et al. 2007): incompressible velocity as the curl
// of a noise potential, one octave per band of eddy sizes.
//
// NoiseTile is the animated band-limited noise every octave and particle reads: a scalar field,
// periodic in space and time, whose energy lies in one octave of wavelengths, [1/2, 1) noise units.
// The seed precomputes animated 3D Perlin noise; this tile is synthesised spectrally instead
// (its curl's energy falling as k^(-5/3) across the octave band, Gaussian in temporal frequency),
// which band-limits it exactly where Perlin noise leaks into neighbouring octaves (the seed notes
// that wavelet noise would band-limit better). It is scaled so the curl of the vector of its three offset copies (2D: the
// rotated gradient of one), interpolated as it is read, has <|curl N|^2> = 2 (measured at random
// points): a potential A N(x / l) then gives velocities of rms sqrt(2) A / l, so A = sqrt(E) l
// (Narain: A_i = u_i l_i, u_i = sqrt(E_i)) gives the kinetic energy 1/2 <|u|^2> = E.
//
// curlOfNodalPotential turns a potential sampled at the nodes of a grid into face velocities that
// are divergence-free to round-off (2D: psi is a stream function; 3D: psi is averaged to the cell
// edges and the edge circulations give the face fluxes, the discrete identity div curl = 0).
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/vec.hpp"

namespace msim::turbulence {

template <int D>
class NoiseTile {
 public:
  static constexpr double kSide = 4.0;    // noise units per tile side
  static constexpr double kPeriod = 8.0;  // time units per period; the noise decorrelates in ~1

  explicit NoiseTile(std::uint64_t seed = 0);
  // The noise at y (noise units) and time t (time units); trilinear (bilinear) in space, linear in
  // time, periodic.
  float value(const Vec<D>& y, double t) const;
  // Component c (0 .. D == 3 ? 2 : 0) of the vector noise: the same tile at a fixed offset per
  // component (the seed's "different offsets" of one noise).
  float component(int c, const Vec<D>& y, double t) const;

 private:
  static constexpr int kSamples = 64, kTimeSamples = 16;  // 8-16 samples per wavelength
  std::vector<float> samples_;  // x fastest, then y, (z), t
};

// u = curl psi on the faces of `u` (over `spec`'s cells). psi holds one value per node (res + 1 per
// axis, x fastest): a vector in 3D, a scalar stream function in its first component in 2D.
template <int D>
void curlOfNodalPotential(const GridSpec<D>& spec, const std::vector<Vecf<3>>& psi, MacGrid<D>& u);

extern template class NoiseTile<2>;
extern template class NoiseTile<3>;

}  // namespace msim::turbulence
