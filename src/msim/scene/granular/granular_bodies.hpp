#pragma once
// bodies[] of a granular scene: rigid bodies two-way coupled with the material (Narain 2011
// ch. 5.3.4), their shapes (sphere, box, convex OBJ mesh, paddle wheel), poses, hinges and contact
// friction; and the world-space triangle mesh of a body for the per-frame PLY and the preview.
#include <vector>

#include "msim/core/triangle_mesh.hpp"
#include "msim/rigid/world.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

Schema granularBodySchema();

// Adds bodies[] to `world` and returns their world indices, in scene order. InputError naming the
// key (bodies[k].mass, bodies[k].shape.file, bodies[k].hinge.pivot, ...) for bad input.
std::vector<int> addSceneBodies(const Scene& scene, rigid::World& world);

// The body's surface in world space (spheres as 12 x 8 latitude-longitude meshes).
TriangleMesh bodyMesh(const rigid::RigidBody& body);

}  // namespace msim::scene
