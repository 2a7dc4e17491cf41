#pragma once
// Extension of a sampled quantity (a face velocity component, or any scalar) from the samples
// where it is known across a band, in order of increasing phi (Selle ch. 4.4.3: "sort cells by
// phi, then solve grad phi . grad u = 0 in increasing-phi order", after Adalsteinsson & Sethian
// 1999). The upwind discretisation of grad phi . grad u = 0 at a sample i,
//
//   sum_k w_k (u_i - u_k) = 0,   w_k = max(0, phi_i - phi_k)  over its known neighbours k,
//
// makes each new value the average of its known neighbours weighted by how much nearer the
// interface they lie, so values travel along the normals away from it: a quantity constant along
// the normals is extended exactly across a planar interface. A sample whose known neighbours all
// have phi >= its own (a kink) takes their plain average. phi must be a distance (reinitialised)
// for the order to follow the normals.
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msim/core/grid.hpp"

namespace msim::numerics {

// u and phi have the same layout (phi sampled at u's positions, e.g. resampleLinear of the cell
// phi onto a face grid); known[i] != 0 marks u[i] as given. Every unknown sample with
// phi <= bandCells * dx that can be reached from a known one gets a value and is marked known.
// Returns the number of samples filled. std::invalid_argument for mismatched layouts.
template <int D>
std::size_t extrapolateAlongNormals(Grid<float, D>& u, std::vector<std::uint8_t>& known, const Grid<float, D>& phi,
                                    double bandCells);

}  // namespace msim::numerics
