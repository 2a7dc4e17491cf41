// Continuous collision detection by the coplanarity cubic (Provot 1997; Bridson, Fedkiw & Anderson
// 2002 sec. 6): analytic crossings of a point through a triangle and of an edge through an edge, a
// miss, a rotating triangle whose first coplanar moment is not a contact, a grazing (double-root)
// contact, coplanar motion solved in the plane (a point or an edge sliding on a floor into a
// triangle or across an edge, collinear edges), pairs touching at the start (reported only when
// they move into each other), random motions cross-checked against fine sampling of the signed
// volume in time, bisection of its sign changes and the proximity at each root, and random motions
// within a plane cross-checked against sampling of the exact in-plane overlap.
#include <gtest/gtest.h>

#include <cmath>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "msim/core/rng.hpp"
#include "msim/solids/collision/ccd.hpp"
#include "msim/solids/collision/proximity.hpp"
#include "random_points.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

using Points = std::array<Vec3, 4>;

constexpr double kEps = 1e-6;

// The four points' signed volume (x1-x0) x (x2-x0) . (x3-x0) at time t, in long double.
long double signedVolume(const Points& x0, const Points& x1, long double t) {
  std::array<Eigen::Matrix<long double, 3, 1>, 4> x;
  for (std::size_t i = 0; i < 4; ++i)
    x[i] = x0[i].cast<long double>() + t * (x1[i].cast<long double>() - x0[i].cast<long double>());
  return (x[1] - x[0]).cross(x[2] - x[0]).dot(x[3] - x[0]);
}

Points at(const Points& x0, const Points& x1, double t) {
  Points x;
  for (std::size_t i = 0; i < 4; ++i) x[i] = x0[i] + t * (x1[i] - x0[i]);
  return x;
}

struct SampledCollision {
  std::optional<double> time;  // the first root with the primitives within eps
  int roots = 0;               // how many roots came before it (or in all, when there is none)
  bool borderline = false;     // a root's distance too close to eps to call
};

// The reference: the volume's sign changes on a fine grid in time, each bisected to a root, and the
// first root at which `distance` is within eps.
template <class Distance>
SampledCollision sampledCollision(const Points& x0, const Points& x1, const Distance& distance) {
  constexpr int kSamples = 4000;
  SampledCollision result;
  long double previous = signedVolume(x0, x1, 0.0L);
  for (int k = 1; k <= kSamples; ++k) {
    long double lo = static_cast<long double>(k - 1) / kSamples, hi = static_cast<long double>(k) / kSamples;
    const long double value = signedVolume(x0, x1, hi);
    if ((previous < 0) != (value < 0)) {
      const bool risingAtLo = previous < 0;
      for (int i = 0; i < 80; ++i) {
        const long double mid = 0.5L * (lo + hi);
        ((signedVolume(x0, x1, mid) < 0) == risingAtLo ? lo : hi) = mid;
      }
      const double root = static_cast<double>(0.5L * (lo + hi));
      const double d = distance(at(x0, x1, root));
      if (std::abs(d - kEps) < 0.5 * kEps) result.borderline = true;
      ++result.roots;
      if (d <= kEps) {
        result.time = root;
        return result;
      }
    }
    previous = value;
  }
  return result;
}

double pointTriangleDistance(const Points& x) { return pointTriangleProximity(x[0], x[1], x[2], x[3]).distance; }
double edgeEdgeDistance(const Points& x) { return edgeEdgeProximity(x[0], x[1], x[2], x[3]).distance; }

}  // namespace

TEST(Ccd, PointFallingThroughAStaticTriangle) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // From z = 1 to z = -3: the plane is crossed a quarter of the way.
  const auto t = pointTriangleCollisionTime({Vec3(0.2, 0.3, 1), a, b, c}, {Vec3(0.2, 0.3, -3), a, b, c}, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.25, 1e-14);
  // Passing beside the triangle's edge: coplanar at t = 0.5 but 0.2 away from it.
  EXPECT_FALSE(pointTriangleCollisionTime({Vec3(0.7, 0.5, 1), a, b, c}, {Vec3(0.7, 0.5, -1), a, b, c}, kEps));
  // Stopping short of it.
  EXPECT_FALSE(pointTriangleCollisionTime({Vec3(0.2, 0.3, 1), a, b, c}, {Vec3(0.2, 0.3, 0.01), a, b, c}, kEps));
}

TEST(Ccd, TriangleSweepingOverAPoint) {
  // The point is still; the triangle rises through it: the same crossing seen from the triangle.
  const Vec3 p(0.2, 0.3, 0.0);
  const Points x0 = {p, Vec3(0, 0, -0.6), Vec3(1, 0, -0.6), Vec3(0, 1, -0.6)};
  const Points x1 = {p, Vec3(0, 0, 0.4), Vec3(1, 0, 0.4), Vec3(0, 1, 0.4)};
  const auto t = pointTriangleCollisionTime(x0, x1, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.6, 1e-14);
}

TEST(Ccd, EdgeCrossingAnEdgeAtTheAnalyticTime) {
  // Edge 1 along x at height 0.6 - 2 t, edge 2 along y at height 0: they meet at t = 0.3.
  const Points x0 = {Vec3(-1, 0.1, 0.6), Vec3(1, 0.1, 0.6), Vec3(0.2, -1, 0), Vec3(0.2, 1, 0)};
  const Points x1 = {Vec3(-1, 0.1, -1.4), Vec3(1, 0.1, -1.4), Vec3(0.2, -1, 0), Vec3(0.2, 1, 0)};
  const auto t = edgeEdgeCollisionTime(x0, x1, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.3, 1e-14);
  // Moved beyond the end of edge 2 (y = 1.5): the lines still meet, the edges do not.
  Points beside0 = x0, beside1 = x1;
  for (const std::size_t i : {0u, 1u}) beside0[i].y() = beside1[i].y() = 1.5;
  EXPECT_FALSE(edgeEdgeCollisionTime(beside0, beside1, kEps));
}

TEST(Ccd, RotatingTriangleReturnsTheFirstCoplanarMomentInContact) {
  // Vertex c of the triangle (0,0,0), (1,0,0), (0,1,z(t)) rises, z = 0.2 + 0.4 t, turning the
  // triangle about its edge ab; the point moves through (0.25, 2 - 2.5 t, 0.52 - 0.5 t). The
  // volume is (t - 0.2)(t - 0.6): at t = 0.2 the point is in the plane but at y = 1.5, beyond the
  // edge bc; at t = 0.6 it is at y = 0.5, inside.
  const Points x0 = {Vec3(0.25, 2, 0.52), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.2)};
  const Points x1 = {Vec3(0.25, -0.5, 0.02), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.6)};
  EXPECT_GT(pointTriangleDistance(at(x0, x1, 0.2)), 0.5) << "the first root is not a contact";
  const auto t = pointTriangleCollisionTime(x0, x1, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.6, 1e-12);
  // Nudging b's motion makes the cubic's leading coefficient tiny instead of zero: same answer.
  Points nudged = x1;
  nudged[2] += Vec3(0, 1e-12, 1e-12);
  const auto tNudged = pointTriangleCollisionTime(x0, nudged, kEps);
  ASSERT_TRUE(tNudged.has_value());
  EXPECT_NEAR(*tNudged, 0.6, 1e-9);
}

TEST(Ccd, GrazingContactAtADoubleRootIsFound) {
  // As above with c rising faster (z = 0.2 + 0.5 t) and the point on (0.25, 2 - 3 t, 0.775 - 1.1 t):
  // the volume is 1.5 (t - 0.5)^2, which touches zero without changing sign, at t = 0.5 with the
  // point at (0.25, 0.5) on the triangle.
  const Points x0 = {Vec3(0.25, 2, 0.775), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.2)};
  const Points x1 = {Vec3(0.25, -1, -0.325), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0.7)};
  const auto t = pointTriangleCollisionTime(x0, x1, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.5, 1e-6);
  // Turned and moved rigidly, the volume is the same polynomial, but rounding now puts its
  // minimum a little above or below zero: found either way.
  Rng rng(19);
  for (int k = 0; k < 20; ++k) {
    const Eigen::Matrix3d rotation =
        Eigen::AngleAxisd(rng.uniform(0, 6), Vec3(rng.normal(), rng.normal(), rng.normal()).normalized())
            .toRotationMatrix();
    const Vec3 shift = randomVector(rng, 2.0);
    Points y0, y1;
    for (std::size_t i = 0; i < 4; ++i) {
      y0[i] = rotation * x0[i] + shift;
      y1[i] = rotation * x1[i] + shift;
    }
    const auto turned = pointTriangleCollisionTime(y0, y1, kEps);
    ASSERT_TRUE(turned.has_value()) << k;
    EXPECT_NEAR(*turned, 0.5, 1e-6) << k;
  }
}

TEST(Ccd, CoplanarMotionIsSolvedInThePlane) {
  // The point slides within the triangle's plane and enters it across the hypotenuse x + y = 1 at
  // x = 0.9, t = 0.1 (the former sampling at t = 0, 1/4, ... reported 1/4).
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  const auto t = pointTriangleCollisionTime({Vec3(1.1, 0.1, 0), a, b, c}, {Vec3(-0.9, 0.1, 0), a, b, c}, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.1, 1e-12);
  // The same tilted by a rotation, so that the cubic's coefficients are only zero to rounding.
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.7, Vec3(1, 2, 3).normalized()).toRotationMatrix();
  const Vec3 shift(0.3, -2.0, 1.1);
  Points x0 = {Vec3(1.1, 0.1, 0), a, b, c}, x1 = {Vec3(-0.9, 0.1, 0), a, b, c};
  for (std::size_t i = 0; i < 4; ++i) {
    x0[i] = rotation * x0[i] + shift;
    x1[i] = rotation * x1[i] + shift;
  }
  const auto tilted = pointTriangleCollisionTime(x0, x1, kEps);
  ASSERT_TRUE(tilted.has_value());
  EXPECT_NEAR(*tilted, 0.1, 1e-12);
  // Edges sliding in a common plane without ever meeting.
  EXPECT_FALSE(edgeEdgeCollisionTime({Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)},
                                     {Vec3(0, 0.2, 0), Vec3(1, 0.2, 0), Vec3(0, 1.2, 0), Vec3(1, 1.2, 0)}, kEps));
}

TEST(Ccd, PointSlidingOnAFloorIntoATriangle) {
  // Everything in the plane y = 0, as cloth lying on a floor. The triangle's edge ab lies on x = 0.
  const Vec3 a(0, 0, 0), b(0, 0, 1), c(1, 0, 0.5);
  const auto t = pointTriangleCollisionTime({Vec3(-1, 0, 0.25), a, b, c}, {Vec3(1, 0, 0.25), a, b, c}, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.5, 1e-9);
  // A sliver 0.06 wide at z = 0.3, crossed between t = 0.45 and 0.48: between samples 1/4 apart.
  const Vec3 apex(0.1, 0, 0.5);
  const auto sliver =
      pointTriangleCollisionTime({Vec3(-0.9, 0, 0.3), a, b, apex}, {Vec3(1.1, 0, 0.3), a, b, apex}, kEps);
  ASSERT_TRUE(sliver.has_value());
  EXPECT_NEAR(*sliver, 0.45, 1e-9);
  // The triangle sliding over the still point instead, at a time off the old sample grid.
  const Vec3 p(-0.3, 0, 0.5), shift(-0.8, 0, 0.1);
  const auto sweeping = pointTriangleCollisionTime({p, a, b, c}, {p, a + shift, b + shift, c + shift}, kEps);
  ASSERT_TRUE(sweeping.has_value());
  EXPECT_NEAR(*sweeping, 0.375, 1e-9);
  // Sliding past the triangle beyond b (z = 1.5): the line x = 0 is crossed 0.5 from the edge.
  EXPECT_FALSE(pointTriangleCollisionTime({Vec3(-1, 0, 1.5), a, b, c}, {Vec3(1, 0, 1.5), a, b, c}, kEps));
  // Sliding towards it but stopping 0.1 short.
  EXPECT_FALSE(pointTriangleCollisionTime({Vec3(-1, 0, 0.25), a, b, c}, {Vec3(-0.1, 0, 0.25), a, b, c}, kEps));
  // Passing the vertex b within eps / 2 (at t = 0.5) is a contact, 2 eps away is not.
  EXPECT_TRUE(pointTriangleCollisionTime({Vec3(-1, 0, 1 + 0.5 * kEps), a, b, c}, {Vec3(1, 0, 1 + 0.5 * kEps), a, b, c}, kEps));
  EXPECT_FALSE(pointTriangleCollisionTime({Vec3(-1, 0, 1 + 2 * kEps), a, b, c}, {Vec3(1, 0, 1 + 2 * kEps), a, b, c}, kEps));
}

TEST(Ccd, EdgeSlidingOnAFloorAcrossAnEdge) {
  // Edge q on x = 0, z in [0, 1]; edge p from (-0.7, 0.4) to (-0.2, 0.6) in (x, z) moving +0.5 in x:
  // its end p1 reaches x = 0 at t = 0.4, at z = 0.6 on q.
  const Vec3 q0(0, 0, 0), q1(0, 0, 1), move(0.5, 0, 0);
  const Vec3 p0(-0.7, 0, 0.4), p1(-0.2, 0, 0.6);
  const auto t = edgeEdgeCollisionTime({p0, p1, q0, q1}, {p0 + move, p1 + move, q0, q1}, kEps);
  ASSERT_TRUE(t.has_value());
  EXPECT_NEAR(*t, 0.4, 1e-9);
  // The roles swapped: q's end crosses p.
  const auto swapped = edgeEdgeCollisionTime({q0, q1, p0, p1}, {q0, q1, p0 + move, p1 + move}, kEps);
  ASSERT_TRUE(swapped.has_value());
  EXPECT_NEAR(*swapped, 0.4, 1e-9);
  // A long edge along z sweeping over a short one's end: r0 = (0, 0.5) is crossed at t = 0.3.
  const Vec3 r0(0, 0, 0.5), r1(0.3, 0, 0.5), s0(-0.3, 0, 0), s1(-0.3, 0, 1), sweep(1, 0, 0);
  const auto over = edgeEdgeCollisionTime({s0, s1, r0, r1}, {s0 + sweep, s1 + sweep, r0, r1}, kEps);
  ASSERT_TRUE(over.has_value());
  EXPECT_NEAR(*over, 0.3, 1e-9);
  // The same motion 1.5 higher in z: the lines cross beyond q's end.
  const Vec3 up(0, 0, 1.5);
  EXPECT_FALSE(edgeEdgeCollisionTime({p0 + up, p1 + up, q0, q1}, {p0 + up + move, p1 + up + move, q0, q1}, kEps));
  // Collinear edges on the line z = 0 sliding into overlap: p's end passes q0 at t = 0.25.
  const auto collinear = edgeEdgeCollisionTime({Vec3(-1.5, 0, 0), Vec3(-0.5, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0)},
                                               {Vec3(0.5, 0, 0), Vec3(1.5, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0)}, kEps);
  ASSERT_TRUE(collinear.has_value());
  EXPECT_NEAR(*collinear, 0.25, 1e-9);
}

TEST(Ccd, PairTouchingAtTheStartIsReportedOnlyWhenItMovesIn) {
  // The point on the triangle's edge x = 0 at t = 0, all in the plane y = 0.
  const Vec3 a(0, 0, 0), b(0, 0, 1), c(1, 0, 0.5), p(0, 0, 0.25);
  const Points x0 = {p, a, b, c};
  const auto moved = [&](const Vec3& point, const Vec3& triangle) {
    return Points{p + point, a + triangle, b + triangle, c + triangle};
  };
  // Moving apart, rigidly, rigidly turned about the floor's normal, or along the edge: never.
  EXPECT_FALSE(pointTriangleCollisionTime(x0, moved(Vec3(-0.5, 0, 0), Vec3::Zero()), kEps));
  EXPECT_FALSE(pointTriangleCollisionTime(x0, moved(Vec3(0.3, 0, -0.2), Vec3(0.3, 0, -0.2)), kEps));
  EXPECT_FALSE(pointTriangleCollisionTime(x0, moved(Vec3(0, 0, 0.5), Vec3::Zero()), kEps));
  const Eigen::Matrix3d turn = Eigen::AngleAxisd(0.3, Vec3::UnitY()).toRotationMatrix();
  Points turned;
  for (std::size_t i = 0; i < 4; ++i) turned[i] = turn * x0[i] + Vec3(0.1, 0, 0.2);
  EXPECT_FALSE(pointTriangleCollisionTime(x0, turned, kEps));
  // Lifting off the floor, out of the triangle's plane.
  EXPECT_FALSE(pointTriangleCollisionTime(x0, moved(Vec3(0.2, 0.5, 0), Vec3::Zero()), kEps));
  // Within eps / 2 outside the edge, moving apart or rigidly: never either.
  const Vec3 off(-0.5 * kEps, 0, 0);
  EXPECT_FALSE(pointTriangleCollisionTime({p + off, a, b, c}, {p + off + Vec3(-0.5, 0, 0), a, b, c}, kEps));
  EXPECT_FALSE(pointTriangleCollisionTime({p + off, a, b, c}, {p + off + Vec3(0, 0, 0.3), a, b, c}, kEps))
      << "sliding along the edge";
  const Vec3 slide(0.2, 0, 0.3);
  EXPECT_FALSE(pointTriangleCollisionTime({p + off, a, b, c}, {p + off + slide, a + slide, b + slide, c + slide}, kEps));
  // Moving into the triangle: at once when touching, when it crosses the edge when eps / 2 away.
  const auto into = pointTriangleCollisionTime(x0, moved(Vec3(0.5, 0, 0), Vec3::Zero()), kEps);
  ASSERT_TRUE(into.has_value());
  EXPECT_EQ(*into, 0.0);
  const auto near = pointTriangleCollisionTime({p + off, a, b, c}, {p + off + Vec3(2, 0, 0), a, b, c}, kEps);
  ASSERT_TRUE(near.has_value());
  EXPECT_NEAR(*near, 0.25 * kEps, 1e-15);
  // The triangle moving onto the touching point.
  const auto onto = pointTriangleCollisionTime(x0, moved(Vec3::Zero(), Vec3(-0.5, 0, 0)), kEps);
  ASSERT_TRUE(onto.has_value());
  EXPECT_EQ(*onto, 0.0);

  // Edges: p1 on q (x = 0) at t = 0; p moving away, rigidly with q, or across q.
  const Vec3 q0(0, 0, 0), q1(0, 0, 1), p0(-0.5, 0, 0.3), p1(0, 0, 0.6);
  const Points e0 = {p0, p1, q0, q1};
  const auto edgesMoved = [&](const Vec3& first, const Vec3& second) {
    return Points{p0 + first, p1 + first, q0 + second, q1 + second};
  };
  EXPECT_FALSE(edgeEdgeCollisionTime(e0, edgesMoved(Vec3(-0.4, 0, 0.1), Vec3::Zero()), kEps));
  EXPECT_FALSE(edgeEdgeCollisionTime(e0, edgesMoved(Vec3(0.2, 0, 0.7), Vec3(0.2, 0, 0.7)), kEps));
  EXPECT_FALSE(edgeEdgeCollisionTime(e0, edgesMoved(Vec3(0, 0, 0.2), Vec3::Zero()), kEps))
      << "p1 sliding along q";
  const auto across = edgeEdgeCollisionTime(e0, edgesMoved(Vec3(0.3, 0, 0), Vec3::Zero()), kEps);
  ASSERT_TRUE(across.has_value());
  EXPECT_EQ(*across, 0.0);
  // Edges crossing already (an X) and moving rigidly: nothing new to report.
  const Points x = {Vec3(-1, 0, 0.5), Vec3(1, 0, 0.5), q0, q1};
  Points xMoved = x;
  for (Vec3& v : xMoved) v += Vec3(0.3, 0, 0.1);
  EXPECT_FALSE(edgeEdgeCollisionTime(x, xMoved, kEps));
}

TEST(Ccd, PairTouchingAtTheStartOutOfPlane) {
  // A point on a triangle (f(0) = 0) lifting off is not a collision; one eps / 2 above it moving
  // down through it is, at the crossing; one eps / 2 above it moving with it is not.
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 0, 1);
  const Vec3 p(0.2, 0, 0.3), up(0, 0.5 * kEps, 0);
  EXPECT_FALSE(pointTriangleCollisionTime({p, a, b, c}, {p + Vec3(0.1, 0.3, 0), a, b, c}, kEps));
  EXPECT_FALSE(pointTriangleCollisionTime({p, a, b, c}, {p + Vec3(0.1, -0.3, 0), a, b, c}, kEps))
      << "distance 0 at the start: it separates whichever side it leaves to";
  const auto down = pointTriangleCollisionTime({p + up, a, b, c}, {p + up - Vec3(0, 1, 0), a, b, c}, kEps);
  ASSERT_TRUE(down.has_value());
  EXPECT_NEAR(*down, 0.5 * kEps, 1e-15);
  const Vec3 slide(0.3, 0.2, -0.1);
  EXPECT_FALSE(pointTriangleCollisionTime({p + up, a, b, c}, {p + up + slide, a + slide, b + slide, c + slide}, kEps));
}

TEST(Ccd, RandomMotionsAgreeWithTimeSampling) {
  Rng rng(17);
  int pointHits = 0, edgeHits = 0, firstRootMissed = 0, compared = 0;
  for (int k = 0; k < 600; ++k) {
    Points x0, x1;
    for (std::size_t i = 0; i < 4; ++i) {
      x0[i] = randomVector(rng, 0.5);
      x1[i] = x0[i] + randomVector(rng, 1.0);
    }
    const std::string what = "trial " + std::to_string(k);
    for (const bool edges : {false, true}) {
      const SampledCollision reference =
          edges ? sampledCollision(x0, x1, edgeEdgeDistance) : sampledCollision(x0, x1, pointTriangleDistance);
      if (reference.borderline) continue;
      ++compared;
      const auto t = edges ? edgeEdgeCollisionTime(x0, x1, kEps) : pointTriangleCollisionTime(x0, x1, kEps);
      ASSERT_EQ(t.has_value(), reference.time.has_value()) << what << (edges ? " edges" : " point");
      if (!t) continue;
      EXPECT_NEAR(*t, *reference.time, 1e-12) << what;
      (edges ? edgeHits : pointHits) += 1;
      if (reference.roots > 1) ++firstRootMissed;
    }
  }
  // The trials exercise what they claim to: crossings of both kinds, some after a coplanar miss.
  EXPECT_GT(compared, 1150);
  EXPECT_GT(pointHits, 20);
  EXPECT_GT(edgeHits, 40);
  EXPECT_GT(firstRootMissed, 8);
}

namespace {

// Exact in-plane overlap in the (x, z) plane, in long double: the point strictly inside the
// triangle, or the edges properly crossing.
long double orient2(const Vec3& a, const Vec3& b, const Vec3& c) {
  const long double ux = static_cast<long double>(b.x()) - a.x(), uz = static_cast<long double>(b.z()) - a.z();
  const long double wx = static_cast<long double>(c.x()) - a.x(), wz = static_cast<long double>(c.z()) - a.z();
  return ux * wz - uz * wx;
}

bool overlapInPlane(const Points& x, bool edges) {
  if (edges) {
    const long double p0 = orient2(x[2], x[3], x[0]), p1 = orient2(x[2], x[3], x[1]);
    const long double q0 = orient2(x[0], x[1], x[2]), q1 = orient2(x[0], x[1], x[3]);
    return ((p0 < 0 && p1 > 0) || (p0 > 0 && p1 < 0)) && ((q0 < 0 && q1 > 0) || (q0 > 0 && q1 < 0));
  }
  const long double area = orient2(x[1], x[2], x[3]);
  const long double s0 = orient2(x[1], x[2], x[0]), s1 = orient2(x[2], x[3], x[0]), s2 = orient2(x[3], x[1], x[0]);
  return area != 0 && s0 * area > 0 && s1 * area > 0 && s2 * area > 0;
}

}  // namespace

TEST(Ccd, RandomMotionsInAPlaneAgreeWithTimeSampling) {
  // Four points in the plane y = 0 moving within it (the cubic vanishes identically): the first
  // sampled time at which the primitives overlap must come right after the reported contact, found
  // again by bisecting the overlap between the last sample without it and the first with it; the
  // same motion turned into a tilted plane gives the same time.
  constexpr int kSamples = 4000;
  Rng rng(23);
  const Eigen::Matrix3d rotation = Eigen::AngleAxisd(0.9, Vec3(2, -1, 3).normalized()).toRotationMatrix();
  const Vec3 shift(0.4, 1.3, -0.7);
  int hits[2] = {0, 0}, betweenSamples = 0, trials = 0;
  for (int k = 0; k < 600; ++k) {
    Points x0, x1;
    for (std::size_t i = 0; i < 4; ++i) {
      x0[i] = randomVector(rng, 0.5);
      x1[i] = x0[i] + randomVector(rng, 1.0);
      x0[i].y() = x1[i].y() = 0.0;
    }
    Points y0, y1;
    for (std::size_t i = 0; i < 4; ++i) {
      y0[i] = rotation * x0[i] + shift;
      y1[i] = rotation * x1[i] + shift;
    }
    for (const bool edges : {false, true}) {
      const std::string what = "trial " + std::to_string(k) + (edges ? " edges" : " point");
      const auto distance = edges ? edgeEdgeDistance : pointTriangleDistance;
      if (overlapInPlane(x0, edges) || distance(x0) <= 2 * kEps) continue;
      ++trials;
      int first = -1;
      for (int s = 1; s <= kSamples && first < 0; ++s)
        if (overlapInPlane(at(x0, x1, static_cast<double>(s) / kSamples), edges)) first = s;
      const auto t = edges ? edgeEdgeCollisionTime(x0, x1, kEps) : pointTriangleCollisionTime(x0, x1, kEps);
      const auto tilted = edges ? edgeEdgeCollisionTime(y0, y1, kEps) : pointTriangleCollisionTime(y0, y1, kEps);
      ASSERT_EQ(t.has_value(), tilted.has_value()) << what;
      if (t) {
        EXPECT_NEAR(*t, *tilted, 1e-9) << what;
      }
      if (first < 0) {
        // No sample overlaps: a report must be a brief overlap between samples or a pass within eps.
        if (t) {
          ++betweenSamples;
          EXPECT_LE(distance(at(x0, x1, *t)), kEps) << what;
        }
        continue;
      }
      ASSERT_TRUE(t.has_value()) << what << ": overlapping at t = " << static_cast<double>(first) / kSamples;
      double lo = static_cast<double>(first - 1) / kSamples, hi = static_cast<double>(first) / kSamples;
      for (int i = 0; i < 60; ++i) {
        const double mid = 0.5 * (lo + hi);
        (overlapInPlane(at(x0, x1, mid), edges) ? hi : lo) = mid;
      }
      EXPECT_NEAR(*t, hi, 1e-9) << what;
      ++hits[edges ? 1 : 0];
    }
  }
  RecordProperty("trials", trials);
  RecordProperty("pointHits", hits[0]);
  RecordProperty("edgeHits", hits[1]);
  EXPECT_GT(trials, 950);
  EXPECT_GT(hits[0], 100);
  EXPECT_GT(hits[1], 120);
  EXPECT_LT(betweenSamples, 5);
}
