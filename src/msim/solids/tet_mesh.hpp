#pragma once
// Tetrahedral meshes of closed shapes for mass-spring solids (Selle ch. 5.2: "BCC tets"): the
// body-centred cubic lattice (cube corners and cube centres) split into tetrahedra, four around
// every face shared by two cubes (the two centres and the face's edge), each kept when its
// centroid lies inside the shape. Every tetrahedron is congruent (no slivers), which keeps the
// springs well conditioned. The solid's mass-spring system: vertices carry a quarter of the mass
// of each tetrahedron around them, every edge gets an edge spring and every tetrahedron an
// altitude spring (ch. 5.3.4).
#include <array>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/geometry/shape.hpp"
#include "msim/solids/mass_spring.hpp"

namespace msim::solids {

struct TetMesh {
  std::vector<Vec3> vertices;
  std::vector<std::array<int, 4>> tetrahedra;  // positively oriented
};

// The BCC tetrahedra of `shape` with lattice spacing `spacing` (cube side) [m]. std::invalid_argument
// for spacing <= 0, an unbounded shape or a lattice of more than 2^31 nodes.
TetMesh bccTetMesh(const geometry::Shape3& shape, double spacing);

struct SolidMaterial {
  double density = 1000.0;        // [kg/m^3]
  double edgeStiffness = 100.0;   // [N]
  double edgeDamping = 0.0;       // [N s/m]
  double altitudeStiffness = 100.0;
  double altitudeDamping = 0.0;
};

// The mass-spring system of the mesh at rest in its shape; std::invalid_argument for a material
// value out of range or a tetrahedron that is inverted or flat (naming it).
MassSpringSystem solidSystem(const TetMesh& mesh, const SolidMaterial& material);

// The triangles on the mesh's boundary (faces of one tetrahedron only), facing outwards, over the
// mesh's vertex indices (the surface a solid shows).
std::vector<std::array<int, 3>> boundaryTriangles(const TetMesh& mesh);

// Six times the signed volume of tetrahedron t of the system (positive as meshed).
double tetrahedronVolume6(const MassSpringSystem& system, const std::array<int, 4>& t);

}  // namespace msim::solids
