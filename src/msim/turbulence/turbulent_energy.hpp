#pragma once
// The energy model of Narain (2011) ch. 3.4: the kinetic energy E_0 of the largest sub-grid eddies
// (size l_0, wavenumber k_0 = 1 / l_0) on the coarse simulation grid, produced by the strain of the
// mean flow U, carried by it, spread by turbulent mixing and passed down the cascade:
//   dE_0/dt + U . grad E_0 = G - Pi + D                                          (eq. 3.5)
//   G = nu_t S(U)^2,  S^2 = sum_ij ((dU_i/dx_j + dU_j/dx_i) / 2)^2                (eq. 3.6, eddy viscosity)
//   Pi = k_0 E_0^(3/2)                                                           (eq. 3.7, Obukhov)
//   D = div(nu_t~ grad E_0),  nu_t~ from E~_0, E_0 Gaussian-filtered over l_0       (eq. 3.8, 3.11)
// with the eddy viscosity of mixing-length theory nu_t = C k_0^-1 sqrt(E_0). The seed writes it
// without a constant (C = 1, "on the order of"); msim's default is the k-epsilon model's
// C_mu = 0.09 (Launder and Spalding 1974), which gives shear flows in equilibrium (G = Pi) the
// measured ratio S k / epsilon = C^(-1/2) = 3.3 (the log layer's -<uv> / k = 0.3) and eddies of
// speed sqrt(E_0) = 0.3 S l_0 instead of S l_0. With C = 1 the eddies of a plume a few cells wide
// are as fast as the plume itself, and mix it away (docs/turbulence.md).
// Integrated by splitting (Kim and Lin 2007, ch. 3.4.2): diffusion implicitly, one axis at a
// time (dimensional splitting; unconditionally stable), advection with the fluid solver's scheme,
// then production and cascade as a pointwise ODE, forward or backward Euler by the sign of
// df/dE_0. The energy of the finer octaves follows from E_0 by the Kolmogorov spectrum, cut off at
// the Kolmogorov microscale k_nu = (Pi / nu^3)^(1/4) (eq. 3.9-3.10), which turns turbulence off
// in calm or viscous flow.
//
// The seed's wavenumbers here are reciprocal lengths, k = 1 / l (not 2 pi / l as in the spectral
// wind): eq. 3.6-3.10 are written that way and their constants assume it.
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/numerics/advection/advector.hpp"

namespace msim::turbulence {

struct TurbulentEnergyParams {
  double largestEddy = 0.0;     // l_0 [m]; <= 0: four grid cells (Narain ch. 3.6)
  double viscosity = 1.5e-5;    // nu [m^2/s] (air); sets the viscous cutoff k_nu
  double initialEnergy = 1e-4;  // E_0 everywhere at the start [m^2/s^2] (ch. 3.4.2: G needs E_0 > 0)
  double eddyViscosityConstant = 0.09;  // C in nu_t = C l_0 sqrt(E_0): k-epsilon's C_mu; the seed: 1
  bool diffusion = true;
  numerics::AdvectionSettings advection;  // the fluid solver's scheme (ch. 3.4.2)
};

template <int D>
class TurbulentEnergy {
 public:
  // std::invalid_argument for a negative viscosity or initial energy, or a constant C <= 0.
  TurbulentEnergy(const GridSpec<D>& spec, const TurbulentEnergyParams& params);

  // Solid cells (> 0.5) hold no energy; their velocity counts as zero in the strain rate (the
  // seed's ghost velocity of the obstacle for the no-slip layer, ch. 3.4.2), as do the walls.
  void setSolid(const Grid<float, D>& solid);

  // One step of eq. 3.5 in the mean flow U (the coarse simulation's face velocities).
  void step(const MacGrid<D>& velocity, double dt);

  // The reaction stage alone: E' = a sqrt(E) - b E^(3/2) over dt, a = C S^2 / k_0, b = k_0
  // (forward Euler while df/dE > 0, stopped at the equilibrium a / b = C S^2 l_0^2; backward Euler
  // otherwise). cStrain2: C S^2.
  static double react(double energy, double cStrain2, double k0, double dt);

  // S(U)^2 at every cell centre (no-slip ghost velocities at walls and solids).
  void strainRateSquared(const MacGrid<D>& velocity, Grid<float, D>& out) const;

  // Eq. 3.9: k_nu = (Pi / nu^3)^(1/4) for the energy E_0 [1/m]; infinite without viscosity.
  double viscousCutoff(double energy) const;
  // Eq. 3.4 and 3.10: the energy of octave i (k_i = 2^i k_0) for E_0, cut off at k_nu. (The seed
  // prints the partial octave's factor as (2 k_i - k_nu) / (2 k_i - k_i), the part beyond the
  // cutoff; its text says the octave is scaled by the part before it, (k_nu - k_i) / k_i.)
  double octaveEnergy(double energy, int octave) const;

  Grid<float, D>& energy() { return energy_; }
  const Grid<float, D>& energy() const { return energy_; }
  const Grid<float, D>& strain2() const { return strain2_; }  // of the last step
  double largestEddy() const { return largestEddy_; }
  double k0() const { return 1.0 / largestEddy_; }
  const TurbulentEnergyParams& params() const { return params_; }
  // sum of E_0 over the fluid cells times the cell volume [m^5/s^2]
  double integral() const;
  // The diffusion stage alone (eq. 3.11), as step() runs it.
  void diffuse(double dt);

 private:
  void filteredEnergy(Grid<float, D>& out) const;
  bool solidAt(const IVec<D>& c) const;

  GridSpec<D> spec_;
  TurbulentEnergyParams params_;
  double largestEddy_;
  Grid<float, D> energy_, strain2_, filtered_, scratch_;
  Grid<float, D> solid_;
  bool hasSolid_ = false;
  numerics::Advector<float, D> advector_;
};

extern template class TurbulentEnergy<2>;
extern template class TurbulentEnergy<3>;

}  // namespace msim::turbulence
