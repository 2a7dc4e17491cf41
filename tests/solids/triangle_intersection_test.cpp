// The exact triangle-triangle intersection test, the referee of cloth collision handling: known
// crossing, separate, touching, coplanar and zero-area cases; vertices exactly on (or one ulp off)
// a tilted plane at decimal coordinates, where a double evaluation of the orientation gets the
// sign wrong; random pairs against a separate segment-triangle check in long double; and exact
// counts of intersecting pairs between and within constructed meshes.
#include <gtest/gtest.h>

#include <cmath>
#include <vector>

#include <Eigen/Geometry>

#include "msim/core/rng.hpp"
#include "msim/solids/collision/triangle_intersection.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

using Triangle = std::array<Vec3, 3>;
using LVec3 = Eigen::Matrix<long double, 3, 1>;

// Symmetric in its arguments, as an intersection test must be.
bool intersect(const Triangle& t, const Triangle& u) {
  const bool forward = trianglesIntersect(t, u), backward = trianglesIntersect(u, t);
  EXPECT_EQ(forward, backward);
  return forward;
}

Triangle shifted(const Triangle& t, const Vec3& d) { return {t[0] + d, t[1] + d, t[2] + d}; }

// The reference: a segment meets a triangle where it crosses the triangle's plane at a point with
// non-negative barycentric coordinates, computed in long double (for triangles in general position).
bool segmentMeetsTriangleLongDouble(const LVec3& p, const LVec3& q, const std::array<LVec3, 3>& t) {
  const LVec3 n = (t[1] - t[0]).cross(t[2] - t[0]);
  const long double dp = n.dot(p - t[0]), dq = n.dot(q - t[0]);
  if ((dp > 0 && dq > 0) || (dp < 0 && dq < 0) || dp == dq) return false;
  const LVec3 x = p + (dp / (dp - dq)) * (q - p);
  for (int e = 0; e < 3; ++e)
    if ((t[(e + 1) % 3] - t[e]).cross(x - t[e]).dot(n) < 0) return false;
  return true;
}

bool trianglesIntersectLongDouble(const Triangle& t, const Triangle& u) {
  std::array<LVec3, 3> tl, ul;
  for (int i = 0; i < 3; ++i) {
    tl[i] = t[i].cast<long double>();
    ul[i] = u[i].cast<long double>();
  }
  for (int e = 0; e < 3; ++e) {
    if (segmentMeetsTriangleLongDouble(tl[e], tl[(e + 1) % 3], ul)) return true;
    if (segmentMeetsTriangleLongDouble(ul[e], ul[(e + 1) % 3], tl)) return true;
  }
  return false;
}

// 2D reference for triangles in the plane z = 0: an edge pair crossing or a vertex inside.
long double cross2(const LVec3& a, const LVec3& b, const LVec3& c) {
  return (b.x() - a.x()) * (c.y() - a.y()) - (b.y() - a.y()) * (c.x() - a.x());
}

bool planarTrianglesOverlapLongDouble(const Triangle& t, const Triangle& u) {
  std::array<LVec3, 3> a, b;
  for (int i = 0; i < 3; ++i) {
    a[i] = t[i].cast<long double>();
    b[i] = u[i].cast<long double>();
  }
  const auto inside = [](const std::array<LVec3, 3>& tri, const LVec3& p) {
    const long double s0 = cross2(tri[0], tri[1], p), s1 = cross2(tri[1], tri[2], p), s2 = cross2(tri[2], tri[0], p);
    return (s0 >= 0 && s1 >= 0 && s2 >= 0) || (s0 <= 0 && s1 <= 0 && s2 <= 0);
  };
  for (int i = 0; i < 3; ++i) {
    if (inside(a, b[i]) || inside(b, a[i])) return true;
    for (int j = 0; j < 3; ++j) {
      const LVec3 &p = a[i], &q = a[(i + 1) % 3], &r = b[j], &s = b[(j + 1) % 3];
      if (cross2(p, q, r) * cross2(p, q, s) < 0 && cross2(r, s, p) * cross2(r, s, q) < 0) return true;
    }
  }
  return false;
}

const Triangle kUnit = {Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0)};

}  // namespace

TEST(Intersection, CrossingAndSeparateTriangles) {
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.2, 0.2, -1), Vec3(0.3, 0.2, 1), Vec3(0.2, 0.3, 1)})) << "piercing";
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.6, 0.6, -1), Vec3(-0.4, 0.6, 1), Vec3(0.6, -0.4, 1)})) << "crossing a band";
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.3, 0.3, -1), Vec3(-1, 0.3, 1), Vec3(0.3, -1, 1)})) << "missing a corner";
  EXPECT_FALSE(intersect(kUnit, shifted(kUnit, Vec3(0, 0, 0.1)))) << "parallel";
  EXPECT_FALSE(intersect(kUnit, {Vec3(2, 0, -1), Vec3(2, 1, 1), Vec3(3, 0, 1)})) << "planes cross elsewhere";
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.6, 0.6, -1), Vec3(0.6, 0.6, 1), Vec3(2, 2, 0)}))
      << "crossing the plane beside the hypotenuse";
}

TEST(Intersection, TouchingTriangles) {
  const double hair = std::ldexp(1.0, -40);
  // A vertex on the face, on an edge, on a vertex; one hair away.
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.25, 0.25, 0), Vec3(0.3, 0.3, 1), Vec3(0.2, 0.4, 1)}));
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.5, 0, 0), Vec3(0.5, -1, 1), Vec3(0.6, -1, 1)}));
  EXPECT_TRUE(intersect(kUnit, {Vec3(1, 0, 0), Vec3(2, 0, 1), Vec3(2, 1, 1)}));
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.25, 0.25, hair), Vec3(0.3, 0.3, 1), Vec3(0.2, 0.4, 1)}));
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.5, -hair, 0), Vec3(0.5, -1, 1), Vec3(0.6, -1, 1)}));
  // An edge of u crossing edge ab of t at (0.5, 0, 0), u in the plane x = 0.5 reaching to y < 0:
  // touching; moved a hair towards +y it cuts into t, a hair towards -y it misses.
  const Triangle u = {Vec3(0.5, -1, 1), Vec3(0.5, 1, -1), Vec3(0.5, -1, -1)};
  EXPECT_TRUE(intersect(kUnit, u));
  EXPECT_TRUE(intersect(kUnit, shifted(u, Vec3(0, hair, 0))));
  EXPECT_FALSE(intersect(kUnit, shifted(u, Vec3(0, -hair, 0))));
}

TEST(Intersection, CoplanarTriangles) {
  EXPECT_TRUE(intersect(kUnit, shifted(kUnit, Vec3(0.3, 0.3, 0)))) << "overlapping";
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.1, 0.1, 0), Vec3(0.3, 0.1, 0), Vec3(0.1, 0.3, 0)})) << "nested";
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.5, 0.5, 0), Vec3(1, 1, 0), Vec3(0.6, 2, 0)})) << "vertex on the hypotenuse";
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.2, 0, 0), Vec3(0.7, 0, 0), Vec3(0.5, -1, 0)})) << "edges overlapping";
  EXPECT_FALSE(intersect(kUnit, shifted(kUnit, Vec3(0.6, 0.6, 0)))) << "apart";
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.2, -0.1, 0), Vec3(0.7, -0.1, 0), Vec3(0.5, -1, 0)})) << "side by side";
  // In the plane x = y, whose projection along z collapses every triangle to a segment.
  const Triangle diagonal = {Vec3(0, 0, 0), Vec3(1, 1, 0), Vec3(0.5, 0.5, 1)};
  EXPECT_TRUE(intersect(diagonal, {Vec3(0.5, 0.5, 0.2), Vec3(2, 2, 0.2), Vec3(2, 2, 3)}));
  EXPECT_FALSE(intersect(diagonal, {Vec3(0.9, 0.9, 0.5), Vec3(2, 2, 0.2), Vec3(2, 2, 3)}));
}

TEST(Intersection, ZeroAreaTriangles) {
  const Triangle piercing = {Vec3(0.2, 0.2, -1), Vec3(0.2, 0.2, 1), Vec3(0.2, 0.2, 0.5)};
  EXPECT_TRUE(intersect(kUnit, piercing)) << "a segment through the face";
  EXPECT_FALSE(intersect(kUnit, shifted(piercing, Vec3(1, 1, 0)))) << "a segment beside it";
  EXPECT_TRUE(intersect(kUnit, {Vec3(-1, 0.5, 0), Vec3(1, 0.5, 0), Vec3(0, 0.5, 0)})) << "a segment in the plane";
  EXPECT_FALSE(intersect(kUnit, {Vec3(-1, 2.5, 0), Vec3(1, 2.5, 0), Vec3(0, 2.5, 0)})) << "in the plane, outside";
  EXPECT_TRUE(intersect(kUnit, {Vec3(0.3, 0.3, 0), Vec3(0.3, 0.3, 0), Vec3(0.3, 0.3, 0)})) << "a point on it";
  EXPECT_FALSE(intersect(kUnit, {Vec3(0.3, 0.3, 0.1), Vec3(0.3, 0.3, 0.1), Vec3(0.3, 0.3, 0.1)})) << "a point off";
  // Both collapsed: segments crossing in space, skew, and collinear overlapping.
  const Triangle alongX = {Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, 0, 0)};
  EXPECT_TRUE(intersect(alongX, {Vec3(0.5, -1, 0), Vec3(0.5, 1, 0), Vec3(0.5, 0.5, 0)}));
  EXPECT_FALSE(intersect(alongX, {Vec3(0.5, -1, 0.1), Vec3(0.5, 1, 0.1), Vec3(0.5, 0.5, 0.1)}));
  EXPECT_TRUE(intersect(alongX, {Vec3(0.9, 0, 0), Vec3(3, 0, 0), Vec3(2, 0, 0)}));
  EXPECT_FALSE(intersect(alongX, {Vec3(1.1, 0, 0), Vec3(3, 0, 0), Vec3(2, 0, 0)}));
}

TEST(Intersection, DecimalVerticesOnATiltedPlaneAreDecidedExactly) {
  // Points (x, y, x/2 + y/4) with decimal x, y lie exactly on the plane z = x/2 + y/4 when the
  // double sum is exact; long double (64-bit significand) holds x/2 + y/4 exactly for these
  // magnitudes, so comparing with it tells. t's vertices and every probe below pass that check.
  const auto onPlane = [](double x, double y) { return Vec3(x, y, x * 0.5 + y * 0.25); };
  const auto exactlyOnPlane = [](const Vec3& p) {
    return static_cast<long double>(p.z()) ==
           static_cast<long double>(p.x()) / 2 + static_cast<long double>(p.y()) / 4;
  };
  const Triangle t = {onPlane(0.1, 0.2), onPlane(0.7, 0.24), onPlane(0.3, 0.9)};
  for (const Vec3& v : t) ASSERT_TRUE(exactlyOnPlane(v));
  const Vec3 normal = (t[1] - t[0]).cross(t[2] - t[0]);  // points up (z > 0)
  ASSERT_GT(normal.z(), 0.0);
  const auto insideFromAbove = [&](const Vec3& p) {  // strictly inside t's projection on the xy plane
    for (int e = 0; e < 3; ++e) {
      const Vec3 a = t[e], b = t[(e + 1) % 3];
      if ((b.x() - a.x()) * (p.y() - a.y()) - (b.y() - a.y()) * (p.x() - a.x()) <= 1e-9) return false;
    }
    return true;
  };
  int probes = 0, doubleSaysOff = 0, doubleSaysBelow = 0;
  for (int i = 1; i < 100; ++i) {
    for (int j = 1; j < 100; ++j) {
      const Vec3 d = onPlane(i / 100.0, j / 100.0);
      if (!exactlyOnPlane(d) || !insideFromAbove(d)) continue;
      ++probes;
      // A vertex exactly on t, the rest of u above: touching.
      const Triangle touching = {d, d + Vec3(0.1, 0, 0.5), d + Vec3(0, 0.1, 0.5)};
      EXPECT_TRUE(intersect(t, touching)) << i << "," << j;
      // The same vertex one ulp higher: all of u strictly above, no contact.
      Vec3 above = d;
      above.z() = std::nextafter(d.z(), 1.0);
      const Triangle apart = {above, d + Vec3(0.1, 0, 0.5), d + Vec3(0, 0.1, 0.5)};
      EXPECT_FALSE(intersect(t, apart)) << i << "," << j;
      // What a double evaluation of the orientation says of these vertices.
      if (normal.dot(d - t[0]) != 0.0) ++doubleSaysOff;
      if (normal.dot(above - t[0]) <= 0.0) ++doubleSaysBelow;
    }
  }
  EXPECT_GT(probes, 100);
  EXPECT_GT(doubleSaysOff, 10) << "the probes include vertices a double evaluation puts off the plane";
  EXPECT_GT(doubleSaysBelow, 10) << "and vertices above it that a double evaluation puts on or below it";
}

TEST(Intersection, RandomPairsAgreeWithLongDoubleSegmentChecks) {
  Rng rng(31);
  const auto randomTriangle = [&](double half) {
    Triangle t;
    for (Vec3& v : t) v = Vec3(rng.uniform(-half, half), rng.uniform(-half, half), rng.uniform(-half, half));
    return t;
  };
  int hits = 0;
  for (int k = 0; k < 4000; ++k) {
    const Triangle t = randomTriangle(1.0), u = randomTriangle(1.0);
    const bool expected = trianglesIntersectLongDouble(t, u);
    EXPECT_EQ(intersect(t, u), expected) << "pair " << k;
    hits += expected;
  }
  EXPECT_GT(hits, 800);
  EXPECT_LT(hits, 3200);
  // Coplanar pairs (all in z = 0) against a 2D check.
  int overlaps = 0;
  for (int k = 0; k < 2000; ++k) {
    Triangle t = randomTriangle(1.0), u = randomTriangle(1.0);
    for (int i = 0; i < 3; ++i) t[i].z() = u[i].z() = 0.0;
    const bool expected = planarTrianglesOverlapLongDouble(t, u);
    EXPECT_EQ(intersect(t, u), expected) << "coplanar pair " << k;
    overlaps += expected;
  }
  EXPECT_GT(overlaps, 400);
  EXPECT_LT(overlaps, 1600);
}

namespace {

struct Mesh {
  std::vector<Vec3> x;
  std::vector<std::array<int, 3>> triangles;
};

// A flat n x n grid of unit squares at z = 0, each split along a diagonal.
Mesh flatGrid(int n) {
  Mesh m;
  for (int j = 0; j <= n; ++j)
    for (int i = 0; i <= n; ++i) m.x.emplace_back(i, j, 0.0);
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      const int v = j * (n + 1) + i;
      m.triangles.push_back({v, v + 1, v + n + 2});
      m.triangles.push_back({v, v + n + 2, v + n + 1});
    }
  return m;
}

// Small standing triangles, one near the centre of lower triangle i of square (i, j), piercing
// only it, for every third square; and as many hovering above the grid, touching nothing.
Mesh needles(int n, int& piercing) {
  Mesh m;
  piercing = 0;
  const auto add = [&](const Vec3& c) {
    const int v = static_cast<int>(m.x.size());
    m.x.push_back(c + Vec3(0, 0, -0.1));
    m.x.push_back(c + Vec3(0.05, 0, 0.1));
    m.x.push_back(c + Vec3(0, 0.05, 0.1));
    m.triangles.push_back({v, v + 1, v + 2});
  };
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) {
      if ((i + 2 * j) % 3 != 0) continue;
      add(Vec3(i + 0.66, j + 0.3, 0.0));  // inside the lower triangle (x > y within the square)
      ++piercing;
      add(Vec3(i + 0.3, j + 0.66, 0.5));  // above the upper one
    }
  return m;
}

}  // namespace

TEST(Intersection, CountsPairsBetweenAndWithinMeshes) {
  const Mesh grid = flatGrid(30);
  int piercing = 0;
  const Mesh spikes = needles(30, piercing);
  EXPECT_EQ(countIntersections(grid.x, grid.triangles, spikes.x, spikes.triangles), static_cast<std::size_t>(piercing));
  EXPECT_EQ(countIntersections(spikes.x, spikes.triangles, grid.x, grid.triangles), static_cast<std::size_t>(piercing));
  // Neighbours share vertices and are skipped; the rest of a flat grid never meets.
  EXPECT_EQ(countSelfIntersections(grid.x, grid.triangles), 0u);
  // One mesh holding both: the same pairs.
  Mesh both = grid;
  const int offset = static_cast<int>(both.x.size());
  both.x.insert(both.x.end(), spikes.x.begin(), spikes.x.end());
  for (const auto& tri : spikes.triangles) both.triangles.push_back({tri[0] + offset, tri[1] + offset, tri[2] + offset});
  EXPECT_EQ(countSelfIntersections(both.x, both.triangles), static_cast<std::size_t>(piercing));
  // A sheet folded through the grid: a vertical strip x = 4.5 crossing every square it passes
  // (two triangles each over 30 squares), touching none of its vertices.
  Mesh wall = both;
  const int w = static_cast<int>(wall.x.size());
  wall.x.insert(wall.x.end(), {Vec3(4.5, -1, -1), Vec3(4.5, 31, -1), Vec3(4.5, -1, 1), Vec3(4.5, 31, 1)});
  wall.triangles.push_back({w, w + 1, w + 3});
  wall.triangles.push_back({w, w + 3, w + 2});
  // The strip's triangles meet z = 0 along x = 4.5, one for y in [-1, 15], the other for y in
  // [15, 31] (their shared diagonal crosses z = 0 at y = 15). Inside the grid each cuts both
  // triangles of 15 squares, and touches, at (4.5, 15, 0) on the row boundary, one more: the
  // triangle across that boundary. The needles stay clear of x = 4.5.
  const std::size_t wallPairs = countSelfIntersections(wall.x, wall.triangles) - static_cast<std::size_t>(piercing);
  EXPECT_EQ(wallPairs, 2u * (30u + 1u));
}

TEST(Intersection, LargeCrumpledMeshHasNone) {
  // 100,352 triangles, gently crumpled so that no two non-neighbours meet (the grid broad phase
  // keeps this linear; its time is in bench/solids_bench.cpp); sanitized builds check a smaller
  // sheet.
  Mesh grid = flatGrid(MSIM_SANITIZE ? 60 : 224);
  Rng rng(37);
  for (Vec3& v : grid.x) v.z() = 0.05 * rng.uniform();
  EXPECT_EQ(countSelfIntersections(grid.x, grid.triangles), 0u);
}
