#pragma once
// The particles' force on the grid (Selle ch. 3.4.2, the method of Figs. 3.3-3.5): every particle
// adds the analytic confinement force of its vorticity,
//   F_p(x) = eps_p (N_p x w_p(x)),  w_p = xi_p(x - x_p) omega_p,  N_p = (x_p - x) / |x_p - x|
// (vortex_kernel.hpp), and the sum over the particles is the body force f of eq. 3.1 (step 2 of
// the pressure-velocity solver: u* += dt f, before the projection). Being a body force, it
// conserves the total vorticity (eq. 3.5), which is the point of the method against the "ad hoc"
// transfer of [47].
//
// Each F_p is evaluated exactly at the face centres of the component it drives (no splat kernel
// in between), so on the grid the force is the point-sampled analytic field. Its staggered
// divergence is second-order small where the kernel is smooth (measured 1.1e-2 |F|/r at r = 19
// cells, order 1.6; tests/fluid_vortex/force_test.cpp). With the clamped Gaussian the tangential
// jump at the cut-off is a vortex sheet whose discrete divergence does not shrink under refinement
// (whole-grid L2 grows as dx^{-1/2}); the projection that follows removes it. The tent kernel has
// no such sheet.
#include "msim/core/block_placement.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/fluid/vortex/vortex_kernel.hpp"
#include "msim/fluid/vortex/vortex_particles.hpp"

namespace msim::fluid {

// velocity_a(face) += dt sum_p F_p(face)_a on every interior face (the domain walls belong to the
// projection) and, with a solid mask (cell-centred, > 0.5 solid), not on faces next to a solid
// cell (as VorticityConfinement). Use dt = 1 on a zeroed MacGrid to get the force field itself.
// Parallel over slabs of faces; each face adds its particles in index order, so the result does not
// depend on the thread count. On one block of a split domain (`placement`, with world positions)
// the walls are the global domain's. std::invalid_argument if dt is negative or not finite.
template <int D>
void addVortexForce(const VortexParticles<D>& particles, VortexKernel kernel, double dt, MacGrid<D>& velocity,
                    const Grid<float, D>* solid = nullptr, const BlockPlacement<D>& placement = {});

// sum_p F_p(x) at one point (every particle visited: for checks and probes, not for grids).
template <int D>
Vec<D> vortexForceAt(const VortexParticles<D>& particles, VortexKernel kernel, const Vec<D>& position);

}  // namespace msim::fluid
