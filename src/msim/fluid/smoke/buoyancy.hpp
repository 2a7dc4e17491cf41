#pragma once
// Buoyancy of smoke (Fedkiw, Stam and Jensen 2001, used by Selle ch. 3): heavy smoke sinks, hot
// gas rises, f = (-alpha rho + beta (T - T_ambient)) e_up, evaluated at cell centres and averaged
// onto the faces normal to the up axis.
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"

namespace msim::fluid {

struct BuoyancyParams {
  double alpha = 0.0;  // sinking per unit smoke density [m/s^2 per kg/m^3]
  double beta = 0.0;   // rise per kelvin above ambient [m/s^2 per K]
  double ambientTemperature = 293.15;  // [K]
  int upAxis = 1;
};

// u_up += dt f on every interior face normal to the up axis whose two cells are fluid.
template <int D>
void addBuoyancy(MacGrid<D>& velocity, const Grid<float, D>& density, const Grid<float, D>& temperature,
                 const BuoyancyParams& params, double dt, const Grid<float, D>* solid = nullptr);

}  // namespace msim::fluid
