#pragma once
// Hinge to the world: body `body` may only rotate about the fixed world `axis` through the fixed
// world `pivot` (a paddle wheel on its shaft). Five velocity-level rows, solved as one block in
// the same sequential-impulse loop as the contacts:
//   point rows   v + omega x r = -beta/dt (x + r - pivot)        (r: body anchor, world frame)
//   angle rows   t_k . omega   =  beta/dt t_k . (a_body x axis)   (t_1, t_2 orthogonal to axis)
// the right-hand sides being Baumgarte drift corrections.
#include "msim/rigid/rigid_body.hpp"

namespace msim::rigid {

struct Hinge {
  int body = 0;
  Vec3 pivot = Vec3::Zero();       // world
  Vec3 axis = Vec3::UnitZ();       // world, unit
  Vec3 localAnchor = Vec3::Zero(); // pivot in the body frame at creation
  Vec3 localAxis = Vec3::UnitZ();  // axis in the body frame at creation
};

// Builds the hinge for the body's current pose (InputError for a zero axis or static body).
Hinge makeHinge(const RigidBody& body, int index, const Vec3& pivot, const Vec3& axis);

}  // namespace msim::rigid
