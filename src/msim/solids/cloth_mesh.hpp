#pragma once
// Cloth as a mass-spring system (Selle ch. 5.2-5.3.3, 6): a triangle mesh whose vertices carry
// the mass of a third of each triangle touching them, with an edge spring on every edge and a
// bending spring across every interior edge (joining the two vertices the edge's triangles do not
// share, ch. 5.3.3). Rectangular patches are generated as quads split along alternating diagonals
// (rows of chevrons, the herring-bone pattern of ch. 5.2), which keeps the cloth from preferring
// one shear direction.
#include "msim/core/triangle_mesh.hpp"
#include "msim/solids/mass_spring.hpp"

namespace msim::solids {

// nu x nv quads over origin + s edgeU + t edgeV, s, t in [0, 1]; vertex (i, j) has index
// j (nu + 1) + i. std::invalid_argument for nu or nv < 1 or parallel edges.
TriangleMesh clothPatch(const Vec3& origin, const Vec3& edgeU, const Vec3& edgeV, int nu, int nv);

struct ClothMaterial {
  double arealDensity = 0.1;   // [kg/m^2]
  double edgeStiffness = 10.0;  // k of eq. 5.1 [N]
  double edgeDamping = 0.0;     // along the spring [N s/m]
  double bendStiffness = 1.0;   // [N]
  double bendDamping = 0.0;     // [N s/m]
};

// The mass-spring system of the mesh at rest in its current shape. std::invalid_argument for a
// material value that is not positive (damping: negative), a degenerate triangle, an index out of
// range, or an edge shared by more than two triangles (not a manifold).
MassSpringSystem clothSystem(const TriangleMesh& mesh, const ClothMaterial& material);

}  // namespace msim::solids
