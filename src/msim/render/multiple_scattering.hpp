#pragma once
// Multiple scattering by the diffusion approximation (Stam 1995, ch. 5.5; seed 004 T15), solved
// by finite volumes and multigrid V-cycles on the cell grid of the density.
//
// What is solved. With the diffuse intensity truncated to its first two moments (P1),
// I_d(x, s) = (phi + 3 F.s) / (4 pi), the fluence phi [W/m^2] obeys eq. (5.23)
//     div(kappa grad phi) - alpha phi + S = 0,   S = q0 - div(q1 / (sigma_tr rho)),
// with kappa = 1 / (3 sigma_tr rho), alpha = sigma_a rho, sigma_tr = (1 - Omega g) sigma_t, and the
// flux F = -kappa grad phi + q1 / (sigma_tr rho) (eq. 5.25). q0 [W/m^3] is the power scattered out
// of the reduced incident light per unit volume (the first-scatter source), q1 [W/m^3] its first
// angular moment (zero for an isotropic phase function).
//   Erratum, decided here: Stam prints kappa = 1 / (sigma_tr rho). Taking the zeroth moment of
// (5.20) gives (1/3) div J1 on the left of (5.21), because the integral of s s over the sphere is
// (4 pi / 3) Id; (5.21) drops that 1/3. With it, kappa = 1 / (3 sigma_tr rho), Ishimaru's diffusion
// constant (Stam's reference [31] for (5.24)); the printed kappa makes light diffuse three times
// too far. The equations keep Stam's form; only the constant carries the 3.
//   Boundary, eq. (5.24) (Marshak: no diffuse light enters): phi + 2 kappa d(phi)/dn - 2 w.n = 0
// with n the outward normal and w = q1 / (sigma_tr rho); then the outgoing flux is F.n = phi / 2.
// It holds on the domain faces and on the boundary of the medium (the faces between a cell with
// density > minDensity and an empty one).
//
// Units and use. The result is the diffuse fluence phi = 4 pi J0_d [W/m^2] per cell (Stam's J0_d
// is the mean diffuse intensity [W/m^2/sr]; his slab display multiplies it by Omega, which is
// sigma_s / sigma_t). A renderer adds the in-scattered radiance sigma_s rho phi / (4 pi)
// [W/m^3/sr] per unit length of a ray (isotropic part of the phase function; the anisotropic
// part F would add sigma_s rho 3 g F.s / (4 pi), not returned). Empty cells return 0.
//   `source` is q0 = sigma_s rho sum_lights E_l tau_l [W/m^3] (irradiance E_l times transmittance
// tau_l), i.e. 4 pi sigma_t rho J0_ri in Stam's notation. `sourceFlux` (optional) is
// q1 = sigma_s rho g sum_lights E_l tau_l s_l [W/m^3] with s_l the unit direction of travel of light
// l (= 4 pi sigma_t rho J1_ri / 3); without it the phase function still enters sigma_tr, but the
// forward push of the first scatter is dropped (exact for g = 0).
//
// Discretisation. Conservative cell-centred finite volumes: the face diffusion constant is
// kappa_f = 1 / (3 sigma_tr rho_f) with rho_f the mean of the two cells' densities (the harmonic
// mean of their kappas: the series conductance of two half cells), and q1 / (sigma_tr rho) is
// averaged the same way. A Marshak face carries the outgoing flux (2 kappa phi_c + h w.n) /
// (h + 4 kappa), from (5.24) with the gradient taken over the half cell to the face. Stam's
// printed stencil, (sum kappa_nb I_nb - 4 kappa I) / (4 h^2), discretises div grad(kappa I) / 4, not
// (5.23), and is not conservative, so it is not offered. Sums of the balance are exact: source
// power = absorbed power + escaped power up to the residual.
//
// Solver. Geometric multigrid V-cycles (Stam's method, 3 red-black Gauss-Seidel relaxations
// before and after each coarse correction), oneTBB-parallel. Coarse cells are active when any
// child is; coarse couplings are half the sum of the fine couplings on the coarse face (exact for
// a constant kappa), absorption and boundary leakage are summed over the children; residuals are
// summed to the parent, corrections interpolated linearly from active coarse cells. The coarsest
// level (<= 4 cells per axis) is solved directly. All memory is allocated before the first cycle.
#include <array>

#include "msim/core/grid.hpp"
#include "msim/core/vec.hpp"

namespace msim::render {

struct DiffusionMedium {
  double extinction = 10.0;  // sigma_t per unit density [m^2/kg]
  double albedo = 0.9;       // Omega = sigma_s / sigma_t, in [0, 1]
  double phaseG = 0.0;       // Henyey-Greenstein asymmetry g = mu_bar / 3 (Stam's first moment), in (-1, 1)
};

struct DiffusionSettings {
  double tolerance = 1e-4;  // stop when |residual| <= tolerance |source| (L2, in power units)
  int maxCycles = 50;
  int relaxations = 3;       // red-black Gauss-Seidel sweeps before and after each coarse correction
  double minDensity = 1e-4;  // [kg/m^3]: below it a cell is empty air (no medium, Marshak face to it)
  // Domain faces normal to axis a are mirrors (no net flux) instead of Marshak boundaries: the
  // symmetry planes of a slab, or a slice cut from a larger medium.
  std::array<bool, 3> reflectingAxes = {false, false, false};
};

struct DiffusionStats {
  int cycles = 0;                 // V-cycles done
  double relativeResidual = 0;    // |b - A phi| / |b| at the end (L2)
  double sourcePower = 0;         // integral of q0 over the medium [W (3D), W/m (2D)]
  double absorbedPower = 0;       // integral of sigma_a rho phi
  double escapedPower = 0;        // outgoing flux phi_face / 2 summed over the Marshak faces
};

// Returns the diffuse fluence phi = 4 pi J0_d [W/m^2] on the cell grid of `density` (see above).
// `source` (and `sourceFlux`) must have the cell-centred layout of `density`. std::invalid_argument
// on a layout mismatch, a non-positive extinction or an albedo or g out of range. The problem is
// singular (light can never leave) only for albedo 1 with mirrors on every side of the medium.
template <int D>
Grid<float, D> solveMultipleScattering(const Grid<float, D>& density, const Grid<float, D>& source,
                                       const DiffusionMedium& medium, const DiffusionSettings& settings,
                                       DiffusionStats* stats = nullptr,
                                       const Grid<Vecf<D>, D>* sourceFlux = nullptr);

}  // namespace msim::render
