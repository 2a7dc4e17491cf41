#pragma once
// Polygon faces and edges of convex polyhedra: the features the separating-axis test and the
// contact clipping work on (polyhedron_contact.hpp), and the planes of the signed distance.
#include "msim/rigid/shapes.hpp"

namespace msim::rigid {

// Sine of the angle below which two edge directions count as parallel (one SAT axis class).
inline constexpr double kParallelSine = 1e-6;

// Fills mesh.faces, edges and edgeDirections from its vertices and triangles. Triangles with
// the same outward normal and plane (within a tolerance relative to the mesh size) are one face
// of a convex mesh; its loop is the 2D convex hull of their vertices, which drops vertices inside
// the face or on the middle of its edges.
void buildConvexFeatures(ConvexMesh& mesh);

// A Box as a polyhedron: corner k at (+-hx, +-hy, +-hz) with the signs from bits 0, 1, 2 of k;
// 6 quads, 12 edges, the 3 axes as edge directions, no triangles.
ConvexMesh boxPolyhedron(const Vec3& halfExtents);

}  // namespace msim::rigid
