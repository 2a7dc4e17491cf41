#pragma once
// Helbing et al.'s (2007) "crowd pressure" P = rho Var(v), the local density times the local
// variance of velocities, which rises above about 0.02 /s^2 where a crowd turns turbulent (Golas
// eq. 4.13). Here the spatial variant: on each cell of a grid, the agents of the (2w+1)^2 cells
// around it give the density (their number over the window's area) and the variance (their mean
// squared deviation from their mean velocity).
#include <span>

#include "msim/core/grid.hpp"
#include "msim/crowd/agents.hpp"

namespace msim::crowd::stress {

// P per cell [1/s^2] (0 where the window holds fewer than 2 agents); `window` w >= 0 cells.
void spatialPressure(std::span<const Vec2f> positions, std::span<const Vec2f> velocities, int window,
                     Grid<float, 2>& pressure);

}  // namespace msim::crowd::stress
