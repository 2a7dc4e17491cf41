#pragma once
// Contacts between two convex polyhedra (boxes as boxPolyhedron, convex meshes) by the
// separating axis test over the face normals of both and the cross products of their edge
// directions (Gottschalk, Lin, Manocha 1996; Ericson, "Real-Time Collision Detection" 2005,
// ch. 4-5; Gregorius, "The Separating Axis Test between Convex Polyhedra", GDC 2013):
//   * the axis of least penetration (largest separation) decides the contact; a face axis is kept
//     over a slightly better one of the other body or an edge pair, so resting contacts do not
//     flicker between features;
//   * face axis: that face is the reference face; the other body's face most anti-parallel to it
//     is clipped against the reference face's side planes (Sutherland-Hodgman); clipped points
//     below the reference plane (or within the margin above it) are contacts, at most 4;
//   * edge axis: one contact at the closest points of the two supporting edges.
#include <vector>

#include <Eigen/Core>

#include "msim/rigid/collision.hpp"

namespace msim::rigid {

// Rigid placement of a shape: world = position + rotation * local.
struct Pose {
  Vec3 position = Vec3::Zero();
  Eigen::Matrix3d rotation = Eigen::Matrix3d::Identity();
  Vec3 toWorld(const Vec3& local) const { return position + rotation * local; }
};

// Appends the contacts of polyhedron a (body ia) with polyhedron b (body ib) whose depth exceeds
// -margin, in the Contact convention (normal from b towards a, point on b's surface).
void collidePolyhedra(const ConvexMesh& a, const Pose& pa, int ia, const ConvexMesh& b,
                      const Pose& pb, int ib, double margin, std::vector<Contact>& out);

}  // namespace msim::rigid
