#pragma once
// Mass, centre of mass and inertia tensor (about the centre of mass) of the rigid shapes.
// Polyhedra use the divergence theorem: volume integrals of 1, x, x^2, xy become surface
// integrals over the triangles (Mirtich 1996; Eberly, "Polyhedral Mass Properties
// (Revisited)", 2002), exact for any closed outward-wound triangle mesh.
#include <vector>

#include <Eigen/Core>

#include "msim/core/triangle_mesh.hpp"
#include "msim/rigid/shapes.hpp"

namespace msim::rigid {

struct MassProperties {
  double mass = 0.0;
  Vec3 centreOfMass = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();  // about centreOfMass, shape axes
};

// All throw InputError for a non-positive or non-finite density/size.
MassProperties sphereMassProperties(const Sphere& sphere, double density);
MassProperties boxMassProperties(const Box& box, double density);
// Throws InputError for an empty, non-closed (every edge must be shared by exactly two
// triangles, once in each direction), inward-wound or zero-volume mesh, or a bad index.
MassProperties meshMassProperties(const TriangleMesh& mesh, double density);
// A ConvexMesh must come from makeConvexMesh (InputError otherwise: its faces are missing).
// A compound sums its parts placed by their poses (parallelAxisInertia); InputError for no parts.
MassProperties shapeMassProperties(const Shape& shape, double density);

// Inertia of a point mass `mass` at `offset` about the origin, m (|d|^2 1 - d d^T): the term the
// parallel-axis theorem adds to an inertia about the centre of mass to move it by `offset`.
Eigen::Matrix3d parallelAxisInertia(double mass, const Vec3& offset);

// Validates `mesh` and returns it as a body-frame ConvexMesh (vertices moved by -centreOfMass,
// polygon faces and edges built by buildConvexFeatures). Convexity itself is not checked:
// contacts and signed distances treat the mesh as convex, which is exact for convex meshes and
// an approximation (closer to its convex hull) otherwise.
ConvexMesh makeConvexMesh(const TriangleMesh& mesh);

// Validates the parts (at least one; each part's shape as for its own body; finite offsets and
// finite non-zero rotations, which are normalised) and returns them as a body-frame Compound:
// offsets moved by minus the centre of mass at uniform density. InputError otherwise, naming the
// part.
Compound makeCompound(std::vector<CompoundPart> parts);

}  // namespace msim::rigid
