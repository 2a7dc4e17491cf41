#pragma once
// Mass, centre of mass and inertia tensor (about the centre of mass) of the rigid shapes.
// Polyhedra use the divergence theorem: volume integrals of 1, x, x^2, xy become surface
// integrals over the triangles (Mirtich 1996; Eberly, "Polyhedral Mass Properties
// (Revisited)", 2002), exact for any closed outward-wound triangle mesh.
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
MassProperties shapeMassProperties(const Shape& shape, double density);

// Validates `mesh` and returns it as a body-frame ConvexMesh (vertices moved by -centreOfMass).
// Convexity itself is not checked: contacts only use the vertices, which is exact for convex
// meshes and an approximation otherwise.
ConvexMesh makeConvexMesh(const TriangleMesh& mesh);

}  // namespace msim::rigid
