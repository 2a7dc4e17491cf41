#pragma once
// Measuring periodic velocity fields on a lattice: the shell-averaged kinetic energy spectrum E(k)
// (the quantity Kolmogorov's k^(-5/3) law speaks of), a least-squares power-law fit to it, and the
// divergence by spectral differentiation. Used by the tests, the benchmarks and the docs' spectra.
#include <cstddef>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::turbulence {

struct ShellSpectrum {
  std::vector<double> wavenumber;   // shell n: the mean |k| of its modes [rad/m] (k = 2 pi |n| / P), n = 1 .. M / 2
  std::vector<double> energy;       // E at that wavenumber [m^3/s^2] (0 for a shell without modes)
  std::vector<std::size_t> modes;   // lattice modes in the shell
};

// E(k) of the periodic field `field` (resolution^D samples, x fastest, tile side `size` [m]),
// u^ = FFT(u) / N, shell n holding the modes with round(|n|) = n. Each mode estimates E at its own
// |k| as its energy 1/2 |u^|^2 times the area of the sphere of radius |n| in mode space (4 pi n^2
// in 3D, 2 pi n in 2D) over dk; a shell reports the mean estimate at its modes' mean |k|. (The
// plain sum over a shell carries the lattice's uneven mode counts and radii: on a 32^3 lattice
// it puts exact Kolmogorov modes 6% low in shell 6; this estimator is within 0.5% from shell 5 up.)
// So sum_shells E dk approximates 1/2 <|u|^2> rather than equalling it.
template <int D>
ShellSpectrum shellSpectrum(std::span<const Vecf<D>> field, int resolution, double size);

struct PowerLawFit {
  double exponent = 0.0;   // E ~ prefactor k^exponent
  double prefactor = 0.0;
  int points = 0;          // shells used
};
// Least squares of log E against log k over the shells with kMin <= k <= kMax and E > 0.
// std::invalid_argument if fewer than 2 shells qualify.
PowerLawFit fitPowerLaw(const ShellSpectrum& spectrum, double kMin, double kMax);

struct DivergenceMeasure {
  double divergenceRms = 0.0;  // rms of div u by spectral differentiation [1/s]
  double gradientRms = 0.0;    // rms of |grad u| (Frobenius), same differentiation: the scale to compare to
};
// Spectral derivatives (i k u^, Nyquist planes dropped) of a periodic lattice field.
template <int D>
DivergenceMeasure spectralDivergence(std::span<const Vecf<D>> field, int resolution, double size);

}  // namespace msim::turbulence
