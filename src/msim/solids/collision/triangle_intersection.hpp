#pragma once
// Exact triangle-triangle intersection: the referee that shows cloth never passes through itself.
// It shares nothing with the collision handling it judges (no tolerances, no proximity, no
// timing): two closed triangles intersect exactly when one's edge meets the other triangle
// (in 3D their intersection is a segment whose ends lie on edges; in a plane, its boundary does),
// and that is decided by the signs of orientation determinants alone. Each sign is computed in
// double with a static error bound (Shewchuk 1997) and, when the bound cannot decide, exactly with
// integer arithmetic on the doubles' exact values (boost::multiprecision::cpp_int), so the answer is
// the exact one for the given doubles: touching counts as intersecting, and coplanar, collinear and
// zero-area configurations are decided in the coordinate planes (see the .cpp).
//
// Coordinates must be finite. Triangles sharing a vertex always touch there: the counts below skip
// pairs that share a vertex index, and trianglesIntersect is meant for triangles that share none.
#include <array>
#include <cstddef>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::solids {

// Whether the closed triangles t and u have a point in common.
bool trianglesIntersect(const std::array<Vec3, 3>& t, const std::array<Vec3, 3>& u);

// The number of pairs of triangles of one mesh that share no vertex and intersect (a uniform grid
// of the triangles' boxes is the broad phase).
std::size_t countSelfIntersections(const std::vector<Vec3>& x, const std::vector<std::array<int, 3>>& triangles);

// The number of pairs (a triangle of mesh A, a triangle of mesh B) that intersect.
std::size_t countIntersections(const std::vector<Vec3>& xA, const std::vector<std::array<int, 3>>& trianglesA,
                               const std::vector<Vec3>& xB, const std::vector<std::array<int, 3>>& trianglesB);

}  // namespace msim::solids
