#pragma once
// Point-versus-triangle queries behind exact mesh distances.
#include "msim/core/vec.hpp"

namespace msim::geometry {

// Closest point to p on the (filled) triangle abc; degenerate triangles are handled.
Vec3 closestPointOnTriangle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

// Signed solid angle [sr] subtended at p by triangle abc (Van Oosterom & Strackee), positive
// when p sees the triangle's back (the side opposite (b-a)x(c-a)). Summed over a closed mesh and
// divided by 4 pi, it is the winding number: +-1 inside, 0 outside.
double solidAngle(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c);

}  // namespace msim::geometry
