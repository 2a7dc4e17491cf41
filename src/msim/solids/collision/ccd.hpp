#pragma once
// Continuous collision detection of cloth primitives by the coplanarity cubic (Provot 1997;
// Bridson, Fedkiw & Anderson 2002 sec. 6; Selle ch. 6.3): four points moving linearly over the
// step, x_i(t) = x0_i + t (x1_i - x0_i) for t in [0, 1], can only pass a point through a triangle or
// an edge through an edge at a time when they are coplanar, i.e. at a root of the cubic
//   f(t) = (x_1(t) - x_0(t)) x (x_2(t) - x_0(t)) . (x_3(t) - x_0(t)).
// Every root in [0, 1] is found, in increasing order, and the first one at which the primitives'
// proximity is within `eps` (plus a rounding allowance of 1e-10 of the largest coordinate) and
// that passes the contact rule below is the collision time. Roots are bracketed between the
// derivative's roots (where f is monotone) and refined by safeguarded Newton, so close pairs of
// roots are not lost; a local extremum of f within rounding of zero (a grazing, tangential
// contact), and either end of the step where f is within rounding of zero, are candidates too.
// Points already close at t = 0 but not coplanar are not reported: repulsions handle proximity,
// this handles crossings.
//
// When f vanishes identically (within rounding) the primitives stay coplanar over the whole step
// and the cubic says nothing about when they meet; the contact is then decided exactly in their
// plane. The plane is projected onto two coordinate axes, dropping the largest component of the
// largest normal of the four points among the configurations at t = 0, 1/2 and 1. In the plane a
// point enters a triangle, and an edge starts to cross an edge, only when a vertex crosses the line
// of a segment of the other primitive: the three edges of the triangle against the point, and each
// endpoint of either edge against the other edge (four pairs). For each pair the 2D orientation
// (b(t) - a(t)) x (v(t) - a(t)) is a quadratic in t, and its roots in [0, 1] (found as for the
// cubic, including double roots and ends within rounding of zero) are the candidates; when it
// vanishes identically the vertex slides along the segment's line, and the candidates are the
// times it passes either end of the segment, the roots of (v - a).(b - a) and (v - b).(a - b). The
// earliest candidate at which the 3D proximity is within eps (relaxed as above) and that passes the
// contact rule is the collision time; a vertex crossing the line beyond the segment's ends is thus
// reported only when it passes within eps of the segment. As out of the plane, a pair that comes
// within eps in the plane without crossing (no vertex reaches the other's segment) is left to the
// repulsions. The projection assumes the common
// plane does not turn edge-on to the dropped axis during the step (it is fixed for primitives lying
// on a floor).
//
// The contact rule: a candidate time t is reported when the pair started farther than eps apart
// (it came within eps during the step), or, for a pair already within eps at t = 0, only when it is
// approaching or crossing at t: its distance at t is smaller than at t = 0 (by more than rounding,
// 1e-12 of the largest coordinate), or it is still decreasing just after t (at t + 1e-4), or, in the
// plane, the vertex crosses the line into the other primitive at t (into the triangle, or to the side
// of the other edge opposite its partner endpoint, so that the edges then cross). A pair that starts
// touching and moves rigidly, in parallel or apart is thus never reported (a caller that makes pairs
// move rigidly can always resolve them), while one that starts touching and moves into the other is
// reported at t = 0. A point exactly on a triangle at t = 0 (distance 0) that moves off its plane is
// not reported: from t = 0 on it separates, whichever side it leaves to.
#include <array>
#include <optional>

#include "msim/core/vec.hpp"

namespace msim::solids {

// x0: positions at the start of the step, x1 at its end; index 0 the point, 1-3 the triangle.
std::optional<double> pointTriangleCollisionTime(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1,
                                                 double eps);

// x0: positions at the start of the step, x1 at its end; 0-1 the first edge, 2-3 the second.
std::optional<double> edgeEdgeCollisionTime(const std::array<Vec3, 4>& x0, const std::array<Vec3, 4>& x1, double eps);

}  // namespace msim::solids
