#pragma once
// Tetrahedral altitude springs (Selle ch. 5.3.4): edge springs alone cannot restore a flattened
// tetrahedron (their forces lie in its plane) and let an inverted one rest inverted. An altitude
// spring acts along one of the tetrahedron's seven altitudes: the four from a vertex to the
// opposite face and the three between opposite edges. Each has length l = 6 V / |u x v| (V the
// signed volume, u and v the face's edges or the two edges), so the shortest is the one with the
// largest |u x v|; Theorem 1: its foot lies inside the face (or both feet inside their edges), so
// the barycentric weights that spread its force onto the vertices are all in [0, 1] and the
// forces stay bounded (a point/face spring picked otherwise can have negative weights and
// unbounded forces). The spring pulls the signed altitude back to that altitude's rest length
// (the seed does not say which rest length applies when the choice switches; each altitude keeps
// its own). A tetrahedron collapsed to a line or a point (every |u x v| zero) gets no force.
#include <array>

#include "msim/core/vec.hpp"

namespace msim::solids {

struct AltitudeChoice {
  int candidate = -1;          // 0-3: vertex i over the opposite face; 4-6: edge pairs 01|23, 02|13, 03|12; -1: none
  std::array<double, 4> weights{};  // the altitude vector is sum_i weights[i] x_i (vertex/first edge +, face/second edge -)
  Vec3 normal = Vec3::Zero();  // unit, along the altitude, oriented with the signed volume
  double altitude = 0.0;       // signed: (sum_i weights[i] x_i) . normal (negative when inverted)
};

// Theorem 1's choice for the tetrahedron x (any orientation; the normal follows the sign of the
// volume so that inverting the tetrahedron flips the altitude's sign).
AltitudeChoice chooseAltitude(const std::array<Vec3, 4>& x);

// The signed altitude of candidate c (as chooseAltitude measures it) at x.
double candidateAltitude(const std::array<Vec3, 4>& x, int candidate);

}  // namespace msim::solids
