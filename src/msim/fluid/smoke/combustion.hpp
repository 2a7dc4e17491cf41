#pragma once
// Creation and spread of fire and smoke creation (Stam ch. 6.4.2-6.4.3) on grid fields:
//   fuel -> flame at the Arrhenius rate S_flame = nu_a exp(-T_a / T) rho_fuel          (eq. 6.3)
//   the reaction heats the gas:      dT = heat_release * (fuel burnt)      (S_T = C_p S_flame T_a)
//   flames cool by radiation:        dT/dt = -C T^4, C = 4 pi sigma_a sigma_SB rho_flame / (rho_f c_p)
//   cooling flames turn into smoke:  S_smoke = nu_b exp(-T / T_b) rho_flame              (ch. 6.4.3)
// Each rate is integrated exactly over the step with the temperature of the step's start (the
// exponentials for fuel and flame, Stam's closed form T = (3 C t + T0^-3)^(-1/3) for radiation),
// so mass moves fuel -> flame -> smoke without loss whatever the step. Spread is emergent: the
// flow carries hot gas to fuel, which ignites once hot enough.
#include "msim/core/grid.hpp"

namespace msim::fluid {

struct CombustionParams {
  double activationTemperature = 2300.0;  // T_a [K] (App. 6.C bonfire)
  double reactionFrequency = 0.28;        // nu_a [1/s]
  double ignitionTemperature = 0.0;       // [K]; below it no reaction (an extension: the seed's
                                          // Arrhenius term leaks a little at any temperature)
  double heatRelease = 1900.0;            // temperature rise per kg/m^3 of fuel burnt [K m^3/kg]
                                          // (T_a c_p,flame / (rho_f c_p,air) with the seed's values)
  double smokeTemperature = 1500.0;       // T_b [K]
  double smokeFrequency = 7.0;            // nu_b [1/s]
  double absorption = 0.4;                // mean absorption cross-section sigma_a [m^2/kg]
  double airHeatCapacity = 1206.0;        // rho_f c_p of the surrounding air [J/(m^3 K)]
  double ambientTemperature = 293.15;     // radiation never cools below this [K]
};

// The rates at one cell, for tests and diagnostics.
double flameCreationRate(const CombustionParams& p, double fuel, double temperature);  // [kg/(m^3 s)]
double smokeCreationRate(const CombustionParams& p, double flame, double temperature);  // [kg/(m^3 s)]
// Stam's closed-form solution of dT/dt = -C T^4 after time t.
double radiativeCooling(double temperature, double C, double t);

struct CombustionTotals {
  double fuelBurnt = 0.0;     // sum over cells of fuel turned into flame this step [kg/m^3 * cells]
  double smokeCreated = 0.0;  // sum of flame turned into smoke
};

// One step of the reactions in every cell (cells with solid > 0.5 are skipped when given).
template <int D>
CombustionTotals react(const CombustionParams& params, double dt, Grid<float, D>& fuel, Grid<float, D>& flame,
                       Grid<float, D>& smoke, Grid<float, D>& temperature, const Grid<float, D>* solid = nullptr);

}  // namespace msim::fluid
