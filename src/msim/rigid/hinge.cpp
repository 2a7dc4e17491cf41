#include "msim/rigid/hinge.hpp"

#include "msim/core/error.hpp"

namespace msim::rigid {

Hinge makeHinge(const RigidBody& body, int index, const Vec3& pivot, const Vec3& axis) {
  if (!(axis.norm() > 0.0) || !axis.allFinite() || !pivot.allFinite())
    throw InputError("rigid hinge: axis must be a finite non-zero vector and pivot finite");
  if (body.isStatic()) throw InputError("rigid hinge: cannot hinge a static body");
  Hinge h;
  h.body = index;
  h.pivot = pivot;
  h.axis = axis.normalized();
  h.localAnchor = body.orientation.conjugate() * (pivot - body.position);
  h.localAxis = body.orientation.conjugate() * h.axis;
  return h;
}

}  // namespace msim::rigid
