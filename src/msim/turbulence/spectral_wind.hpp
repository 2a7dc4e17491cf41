#pragma once
// Turbulent wind fields by spectral synthesis (Stam 1995, ch. 3.3.2 and 3.4.3): a homogeneous,
// isotropic, incompressible random velocity field with the Kolmogorov spectrum, on a lattice that
// is periodic in space and in time (the 4D lattice of ch. 6.3.2), sampled anywhere by
// (quadri)linear interpolation with wrap-around (App. 6.B).
//
// Synthesis, per lattice mode (k, kappa) (k = 2 pi n / P for the signed FFT index n, P the tile
// size; kappa = 2 pi l / T for the time index l, T the time period):
//   u^(k, kappa) = sqrt(Phi_m^2(k) w_k(kappa) dk^m) P(k) v,   P(k) = I - k k^T / k^2   (eq. 3.13)
// with Phi_m^2 = E(k) Gamma(m/2) / (pi^(m/2) (m - 1) k^(m - 1)) (E / (4 pi k^2) in 3D, eq. 3.14;
// E / (pi k) in 2D), v a vector of complex white noise A e^(2 pi i psi) (A standard normal, psi
// uniform, ch. 3.3.1), and w_k the temporal spread of eq. 3.27-3.28: a Gaussian in kappa of standard
// deviation k sigma (small eddies decorrelate faster), normalised to sum to 1 over the lattice's
// time frequencies so each shell keeps its energy (the seed normalises the continuous integral).
// The mirror mode (-k, -kappa) gets the complex conjugate, so the inverse FFT is real (Fig. 3.6);
// the mean (k = 0) and the Nyquist planes (whose waves are their own mirror images, where a
// derivative, and so the divergence, is undefined) are left empty. Every mode draws its noise from
// its own stream (Rng::split by mode index), so a seed gives the same field on any thread count.
//
// Simplification: the seed's lattice wavenumbers are printed in index units with an OCR-damaged
// scale (seed notes T6); here they are physical (rad/m), so the spectrum's parameters are
// physical (epsilon in m^2/s^3, eddy sizes in m) and the seed's "1/L = 4" is L = P / 4.
#include <array>
#include <cstdint>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/turbulence/kolmogorov_spectrum.hpp"

namespace msim::turbulence {

struct SpectralWindParams {
  KolmogorovSpectrum spectrum;
  int resolution = 16;   // M lattice samples per spatial axis (Stam App. 6.C: 16)
  int timeSamples = 16;  // M_t samples over the time period (16; 1 = frozen in time)
  double size = 1.0;     // P, side of the periodic tile [m]
  double period = 1.0;   // T, time period of the lattice [s]
  // sigma [m/s]: the temporal spectrum of wavenumber k has standard deviation k sigma (eq. 3.28),
  // so an eddy of size l decorrelates in about l / (2 pi sigma). < 0: the field's own speed rms
  // (small eddies swept past by the large ones, Tennekes' random sweeping); 0: frozen.
  double sweep = -1.0;
  std::uint64_t seed = 0;
};

template <int D>
class SpectralWind {
 public:
  // Synthesises the lattice. InputError (naming `where`) for bad parameters: see validate().
  SpectralWind(const SpectralWindParams& params, const std::string& where = "wind");

  // Velocity [m/s] at position x [m] and time t [s]: linear interpolation in space and time of the
  // 2^(D+1) surrounding lattice samples, indices wrapped (App. 6.B). Periodic with period P in
  // every axis and T in time.
  Vec<D> velocity(const Vec<D>& x, double t) const;

  // Component `axis` of the lattice blended linearly to time t (M^D values, x fastest): the time
  // interpolation of velocity() done once for a whole slice.
  void componentAt(int axis, double t, std::vector<float>& slice) const;

  // The lattice: sample (i_0 .. i_{D-1}, l) at index i_0 + M (i_1 + M (... + M l)), each a velocity.
  std::span<const Vecf<D>> samples() const { return samples_; }
  // The samples of time slice l (M^D of them, x fastest).
  std::span<const Vecf<D>> timeSlice(int l) const;
  const SpectralWindParams& params() const { return params_; }
  double cellSize() const { return params_.size / params_.resolution; }
  double sweep() const { return sweep_; }

  // <|u|^2> the synthesis aims at: the sum over the lattice's modes of their variances (the
  // prescribed spectrum integrated on the lattice), against 2 int E dk of the continuous spectrum.
  double latticeVariance() const { return latticeVariance_; }
  // Largest |imaginary part| the inverse FFT left, relative to the largest |real part| (round-off:
  // the mirror modes are exact conjugates).
  double imaginaryResidue() const { return imaginaryResidue_; }

  // InputError naming `where` for: spectrum (KolmogorovSpectrum::validate); resolution < 4 or
  // timeSamples < 1; size, period not positive; sweep not finite; a largest eddy above the tile
  // (the longest wave the tile holds is P); a smallest eddy below two lattice cells (the shortest
  // it resolves, the Nyquist wavelength 2 P / M).
  static void validate(const SpectralWindParams& params, const std::string& where);

 private:
  SpectralWindParams params_;
  double sweep_ = 0.0;
  std::vector<Vecf<D>> samples_;
  double latticeVariance_ = 0.0;
  double imaginaryResidue_ = 0.0;
};

extern template class SpectralWind<2>;
extern template class SpectralWind<3>;

}  // namespace msim::turbulence
