#pragma once
// The collision loop's test scene, shared by the cloth tests on one process and split among
// processes: a 0.6 m square of n x n quads hanging edge down (tilted 5 degrees) above a floor with
// friction 0.5, implicit springs, the loop in 8 inner steps with a thickness of 5 mm and strain
// limited to 0.1.
#include <memory>

#include "msim/geometry/analytic_shapes.hpp"
#include "msim/solids/cloth_collision_loop.hpp"
#include "msim/solids/cloth_mesh.hpp"

namespace msim::solids {

struct FloorDrop {
  TriangleMesh mesh;
  MassSpringSystem system;
  BodyContact floor;
  NewmarkSettings newmark;
  ClothCollisionSettings settings;
};

inline FloorDrop floorDrop(int quads) {
  FloorDrop d;
  d.mesh = clothPatch(Vec3(-0.3, 0.7, 0.0), Vec3(0.6, 0.0, 0.0), Vec3(0.0, -0.6, 0.05), quads, quads);
  d.system = clothSystem(d.mesh, {.edgeStiffness = 20.0, .edgeDamping = 0.002, .bendStiffness = 0.05, .bendDamping = 0.0001});
  d.floor.addBody({std::make_shared<geometry::Plane<3>>(Vec3::Zero(), Vec3(0.0, 1.0, 0.0)), Vec3::Zero(), 0.5});
  d.newmark.implicitSprings = true;
  d.newmark.cgTolerance = 1e-4;
  d.settings.innerSteps = 8;
  d.settings.repulsion.thickness = 0.005;
  d.settings.repulsion.stiffness = 800.0;  // about k / l0 of the edge springs
  d.settings.strainLimit = 0.1;
  return d;
}

}  // namespace msim::solids
