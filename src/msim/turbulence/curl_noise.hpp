#pragma once
// Curl noise (Narain 2011 ch. 3.5, after Bridson et al. 2007): incompressible velocity as the curl
// of a noise potential, one octave per band of eddy sizes.
//
// NoiseTile is the animated band-limited vector noise every octave and particle reads: periodic in
// space and time, its energy in one octave of wavelengths, [1/2, 1) noise units. The seed
// precomputes animated 3D Perlin noise and takes the three components as different offsets of it;
// this tile is synthesised spectrally instead (its curl's energy falling as k^(-5/3) across the
// octave band, Gaussian in temporal frequency), which band-limits it exactly where Perlin noise
// leaks into neighbouring octaves (the seed notes that wavelet noise would band-limit better), and
// its three components are independent realisations stored side by side, so one lookup's taps
// serve all three (the potential's evaluation is the seed's bottleneck, ch. 3.6.2). It is scaled so
// the curl of the vector noise (2D: the rotated gradient of the scalar), interpolated as it is
// read, has <|curl N|^2> = 1 (measured at random points): a potential A N(x / l) then gives
// velocities of rms A / l, so Narain's A_i = u_i l_i gives eddies of "magnitude u_i" (ch. 3.5.1),
// u_i = sqrt(E_i): <|u|^2> = E_i.
//
// curlOfNodalPotential turns a potential sampled at the nodes of a grid into face velocities that
// are divergence-free to round-off (2D: psi is a stream function; 3D: psi is averaged to the cell
// edges and the edge circulations give the face fluxes, the discrete identity div curl = 0).
#include <array>
#include <cmath>
#include <cstdint>
#include <type_traits>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/linear_taps.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/core/vec.hpp"

namespace msim::turbulence {

template <int D>
class NoiseTile {
 public:
  static constexpr double kSide = 4.0;    // noise units per tile side
  static constexpr double kPeriod = 8.0;  // time units per period; the noise decorrelates in ~1
  static constexpr int kComponents = D == 3 ? 3 : 1;  // a vector potential in 3D, a stream function in 2D
  static constexpr int kSamples = 64, kTimeSamples = 16;  // per side and per period: 8-16 per wavelength

  explicit NoiseTile(std::uint64_t seed = 0);
  // The linear tap of time t (time units), periodic: computed once for many lookups at one time.
  LinearTap timeTap(double t) const;

  // Lookups along the tile's first axis at fixed other coordinates and time (how the synthesis
  // walks a row of nodes): the 2^D sample rows bracketing y[1 ..] and t, with their weights.
  static constexpr int kRowCorners = 1 << D;
  struct Row {
    std::array<std::size_t, kRowCorners> offset;
    std::array<float, kRowCorners> weight;
  };
  Row row(const Vec<D>& y, const LinearTap& time) const;
  // The noise at first coordinate x on `row`: trilinear (bilinear) in space, linear in time with
  // the blend's variance restored, periodic. Components past kComponents are zero.
  Vecf<3> onRow(const Row& row, double x) const {
    static_assert((kSamples & (kSamples - 1)) == 0, "the wrap is a mask");
    const float g = static_cast<float>(x) * static_cast<float>(kSamples / kSide);
    const float lower = std::floor(g);
    const auto i = static_cast<std::uint32_t>(static_cast<std::int32_t>(lower)) & (kSamples - 1u);
    const std::uint32_t j = (i + 1u) & (kSamples - 1u);
    const float f = g - lower;
    Sample sum = samples_[0] * 0.0f;
    for (int c = 0; c < kRowCorners; ++c) {
      const Sample* s = samples_.data() + row.offset[c];
      sum += row.weight[c] * (s[i] + f * (s[j] - s[i]));
    }
    if constexpr (D == 3) {
      return Vecf<3>(sum[0], sum[1], sum[2]);
    } else {
      return Vecf<3>(sum, 0.0f, 0.0f);
    }
  }
  // The noise at y (noise units) and time t.
  Vecf<3> vector(const Vec<D>& y, double t) const { return onRow(row(y, timeTap(t)), y[0]); }

 private:
  // One sample: the components side by side (3D: padded to 16 bytes, one vector load).
  using Sample = std::conditional_t<D == 3, Eigen::Array4f, float>;
  std::vector<Sample> samples_;  // x fastest, then y, (z), t
  float adjacentCorrelation_ = 0.0f;  // of two samples one time step apart (row() corrects the blend)
};

// u = curl psi on the faces of `u` (over `spec`'s cells). psi holds one value per node (res + 1 per
// axis, x fastest): a vector in 3D, a scalar stream function in its first component in 2D.
template <int D>
void curlOfNodalPotential(const GridSpec<D>& spec, const std::vector<Vecf<3>>& psi, MacGrid<D>& u);

extern template class NoiseTile<2>;
extern template class NoiseTile<3>;

}  // namespace msim::turbulence
