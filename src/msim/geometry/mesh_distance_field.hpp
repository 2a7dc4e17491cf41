#pragma once
// Signed distance of a closed triangle mesh sampled on a grid, via OpenVDB's mesh-to-level-set.
#include "msim/core/grid.hpp"
#include "msim/core/triangle_mesh.hpp"

namespace msim::geometry {

// Signed distance [m] at every cell centre of `spec` (negative inside). Distances are exact within
// a narrow band of `halfBandCells` cells around the surface; farther away the magnitude is clamped
// to halfBandCells * dx, while the sign (inside/outside, from OpenVDB's interior flood fill) stays
// exact. The mesh should be closed; it may be wound either way.
Grid<float, 3> meshDistanceField(const TriangleMesh& mesh, const GridSpec<3>& spec, float halfBandCells = 3.0f);

}  // namespace msim::geometry
