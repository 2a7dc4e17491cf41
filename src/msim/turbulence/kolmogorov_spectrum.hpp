#pragma once
// The Kolmogorov energy spectrum of Stam (1995) ch. 3.4.2 with its inertial range made explicit:
// E(k) = C_K epsilon^(2/3) k^(-5/3) for 2 pi / L <= k <= 2 pi / l_0, zero outside (the seed leaves
// the spectrum outside the inertial range open; ch. 3.4.2 puts the energy-containing eddies at L
// and the dissipation at l_0, and we cut there). k is the angular wavenumber 2 pi / wavelength
// [rad/m], so an eddy of size L has k = 2 pi / L, and E integrates to the kinetic energy per unit
// mass: int E dk = 1/2 <|u|^2>.
#include <string>

namespace msim::turbulence {

struct KolmogorovSpectrum {
  double kolmogorovConstant = 1.5;  // C_K (Stam ch. 3.4.2: about 1.5)
  double dissipation = 1.0;         // epsilon, rate of dissipation of kinetic energy [m^2/s^3]
  double largestEddy = 1.0;         // L [m]: no energy at k < 2 pi / L
  double smallestEddy = 0.1;        // l_0 [m]: no energy at k > 2 pi / l_0

  double lowWavenumber() const;   // 2 pi / L [rad/m]
  double highWavenumber() const;  // 2 pi / l_0 [rad/m]
  // E(k) [m^3/s^2]; 0 outside [2 pi / L, 2 pi / l_0].
  double energy(double k) const;
  // int E dk = 3/2 C_K epsilon^(2/3) (k_L^(-2/3) - k_0^(-2/3)) = 1/2 <|u|^2> [m^2/s^2].
  double kineticEnergy() const;
  // sqrt(<|u|^2>) = sqrt(2 kineticEnergy()) [m/s].
  double speedRms() const;
  // The dissipation that gives the speed rms u (> 0) with this spectrum's constant and range.
  double dissipationForSpeedRms(double u) const;

  // InputError naming `where` (a scene key) if C_K or epsilon is not positive and finite
  // ("negative energy"), L or l_0 not positive, or l_0 >= L (the cutoff below the largest scale).
  void validate(const std::string& where) const;
};

}  // namespace msim::turbulence
