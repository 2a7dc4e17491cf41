// Closest points of cloth primitives (Bridson, Fedkiw & Anderson 2002 sec. 6): point-triangle and
// edge-edge proximity against a brute-force reference that samples the primitives densely and
// zooms in on the best sample (the squared distance is convex in the barycentric parameters, so
// the zoom cannot leave the minimum behind), on random, degenerate and parallel configurations;
// the weights reproduce the closest points and the normals point from one to the other.
#include <gtest/gtest.h>

#include <algorithm>
#include <array>
#include <cmath>
#include <functional>
#include <optional>
#include <string>

#include <Eigen/Geometry>

#include "msim/core/rng.hpp"
#include "msim/solids/collision/proximity.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

// The minimum of `distance` over parameters (u, v), each sample first mapped into the domain by
// `clampToDomain`: a uniform grid over [0, 1]^2, then grids shrinking around the best sample.
double sampledMinimum(const std::function<double(double, double)>& distance,
                      const std::function<void(double&, double&)>& clampToDomain) {
  const auto at = [&](double u, double v) {
    clampToDomain(u, v);
    return distance(u, v);
  };
  constexpr int kCoarse = 100, kHalfWindow = 10;
  double best = INFINITY, bestU = 0.0, bestV = 0.0;
  for (int i = 0; i <= kCoarse; ++i)
    for (int j = 0; j <= kCoarse; ++j) {
      double u = static_cast<double>(i) / kCoarse, v = static_cast<double>(j) / kCoarse;
      clampToDomain(u, v);
      if (const double d = distance(u, v); d < best) best = d, bestU = u, bestV = v;
    }
  for (double spacing = 0.5 / kCoarse; spacing > 1e-12; spacing *= 0.5) {
    const double centreU = bestU, centreV = bestV;
    for (int i = -kHalfWindow; i <= kHalfWindow; ++i)
      for (int j = -kHalfWindow; j <= kHalfWindow; ++j) {
        double u = centreU + i * spacing, v = centreV + j * spacing;
        clampToDomain(u, v);
        if (const double d = at(u, v); d < best) best = d, bestU = u, bestV = v;
      }
  }
  return best;
}

// (u, v) mapped into the triangle u, v >= 0, u + v <= 1 (the weights of b and c).
void clampToTriangle(double& u, double& v) {
  u = std::max(u, 0.0);
  v = std::max(v, 0.0);
  if (u + v > 1.0) {
    const double excess = 0.5 * (u + v - 1.0);
    u = std::clamp(u - excess, 0.0, 1.0);
    v = 1.0 - u;
  }
}

void clampToSquare(double& u, double& v) {
  u = std::clamp(u, 0.0, 1.0);
  v = std::clamp(v, 0.0, 1.0);
}

double sampledPointTriangleDistance(const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c) {
  return sampledMinimum([&](double u, double v) { return (p - (a + u * (b - a) + v * (c - a))).norm(); },
                        clampToTriangle);
}

double sampledEdgeEdgeDistance(const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1) {
  return sampledMinimum([&](double s, double t) { return ((p0 + s * (p1 - p0)) - (q0 + t * (q1 - q0))).norm(); },
                        clampToSquare);
}

Vec3 randomPoint(Rng& rng) { return Vec3(rng.uniform(-1, 1), rng.uniform(-1, 1), rng.uniform(-1, 1)); }

// The result's own consistency: weights in [0, 1] summing to 1 that reproduce a point at
// `distance`, and a unit normal along p minus that point.
void expectConsistent(const PointTriangleProximity& r, const Vec3& p, const Vec3& a, const Vec3& b, const Vec3& c,
                      const std::string& what) {
  EXPECT_GE(r.weights.minCoeff(), 0.0) << what;
  EXPECT_LE(r.weights.maxCoeff(), 1.0) << what;
  EXPECT_NEAR(r.weights.sum(), 1.0, 1e-15) << what;
  const Vec3 closest = r.weights[0] * a + r.weights[1] * b + r.weights[2] * c;
  EXPECT_NEAR((p - closest).norm(), r.distance, 1e-14) << what;
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-14) << what;
  if (r.distance > 1e-9) {
    EXPECT_LT((p - closest - r.distance * r.normal).norm(), 1e-13) << what;
  }
}

void expectConsistent(const EdgeEdgeProximity& r, const Vec3& p0, const Vec3& p1, const Vec3& q0, const Vec3& q1,
                      const std::string& what) {
  EXPECT_GE(r.s, 0.0) << what;
  EXPECT_LE(r.s, 1.0) << what;
  EXPECT_GE(r.t, 0.0) << what;
  EXPECT_LE(r.t, 1.0) << what;
  const Vec3 gap = (p0 + r.s * (p1 - p0)) - (q0 + r.t * (q1 - q0));
  EXPECT_NEAR(gap.norm(), r.distance, 1e-14) << what;
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-14) << what;
  if (r.distance > 1e-9) {
    EXPECT_LT((gap - r.distance * r.normal).norm(), 1e-13) << what;
  }
}

// A closest distance against the least of dense samples: never above it, and within 1e-6 of it.
void expectMatchesSampling(double distance, double sampled, const std::string& what) {
  EXPECT_LE(distance, sampled * (1.0 + 1e-12)) << what << ": no sample is closer";
  EXPECT_NEAR(distance, sampled, 1e-6 * sampled) << what;
}

}  // namespace

TEST(CollisionGeometry, PointTriangleMatchesDenseSamplingOnRandomCases) {
  Rng rng(3);
  for (int k = 0; k < 150; ++k) {
    const Vec3 a = randomPoint(rng), b = randomPoint(rng), c = randomPoint(rng);
    // Points near the triangle as well as far: every Voronoi region gets visited.
    const Vec3 p = (a + b + c) / 3.0 + (k % 2 == 0 ? 0.3 : 2.0) * randomPoint(rng);
    const PointTriangleProximity r = pointTriangleProximity(p, a, b, c);
    const std::string what = "case " + std::to_string(k);
    expectConsistent(r, p, a, b, c, what);
    expectMatchesSampling(r.distance, sampledPointTriangleDistance(p, a, b, c), what);
  }
}

TEST(CollisionGeometry, PointTriangleRegions) {
  const Vec3 a(0, 0, 0), b(1, 0, 0), c(0, 1, 0);
  // Face: straight above, the normal up.
  PointTriangleProximity r = pointTriangleProximity(Vec3(0.2, 0.3, 0.5), a, b, c);
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  EXPECT_TRUE(r.weights.isApprox(Vec3(0.5, 0.2, 0.3), 1e-15));
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ(), 1e-15));
  // Below: the normal points down, towards the point.
  r = pointTriangleProximity(Vec3(0.2, 0.3, -0.5), a, b, c);
  EXPECT_TRUE(r.normal.isApprox(-Vec3::UnitZ(), 1e-15));
  // Vertex region beyond a.
  r = pointTriangleProximity(Vec3(-1, -2, 2), a, b, c);
  EXPECT_TRUE(r.weights.isApprox(Vec3(1, 0, 0)));
  EXPECT_NEAR(r.distance, 3.0, 1e-15);
  // Edge region of bc: the foot (0.5, 0.5, 0).
  r = pointTriangleProximity(Vec3(1, 1, 0), a, b, c);
  EXPECT_TRUE(r.weights.isApprox(Vec3(0, 0.5, 0.5), 1e-15));
  EXPECT_NEAR(r.distance, std::sqrt(0.5), 1e-15);
  // On the triangle: distance 0, the triangle's normal.
  r = pointTriangleProximity(Vec3(0.25, 0.25, 0), a, b, c);
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ(), 1e-15));
}

TEST(CollisionGeometry, PointTriangleHandlesDegenerateTriangles) {
  Rng rng(5);
  for (int k = 0; k < 60; ++k) {
    const Vec3 a = randomPoint(rng), d = randomPoint(rng), p = 1.5 * randomPoint(rng);
    // Collinear (c between a and b, or beyond), two coincident vertices, all coincident.
    const std::array<std::array<Vec3, 3>, 4> triangles = {{{a, Vec3(a + d), Vec3(a + 0.3 * d)},
                                                           {a, Vec3(a + d), Vec3(a + 1.7 * d)},
                                                           {a, a, Vec3(a + d)},
                                                           {a, a, a}}};
    for (std::size_t t = 0; t < triangles.size(); ++t) {
      const auto& [x, y, z] = triangles[t];
      const PointTriangleProximity r = pointTriangleProximity(p, x, y, z);
      const std::string what = "case " + std::to_string(k) + " kind " + std::to_string(t);
      ASSERT_TRUE(std::isfinite(r.distance)) << what;
      ASSERT_TRUE(r.normal.allFinite()) << what;
      expectConsistent(r, p, x, y, z, what);
      EXPECT_NEAR(r.distance, sampledPointTriangleDistance(p, x, y, z), 1e-6 * (r.distance + 1e-9)) << what;
    }
  }
  // A point on a degenerate triangle still gets a unit normal (perpendicular to its line).
  const PointTriangleProximity r = pointTriangleProximity(Vec3(0.5, 0, 0), Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(2, 0, 0));
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-15);
  EXPECT_NEAR(r.normal.x(), 0.0, 1e-15);
}

TEST(CollisionGeometry, EdgeEdgeMatchesDenseSamplingOnRandomCases) {
  Rng rng(9);
  for (int k = 0; k < 150; ++k) {
    const Vec3 p0 = randomPoint(rng), p1 = randomPoint(rng), q0 = randomPoint(rng), q1 = randomPoint(rng);
    const EdgeEdgeProximity r = edgeEdgeProximity(p0, p1, q0, q1);
    const std::string what = "case " + std::to_string(k);
    expectConsistent(r, p0, p1, q0, q1, what);
    expectMatchesSampling(r.distance, sampledEdgeEdgeDistance(p0, p1, q0, q1), what);
  }
}

// The repulsions' shortcut: the full computation's answer whenever its closest points lie inside
// both edges, none otherwise.
TEST(CollisionGeometry, EdgeEdgeInteriorAgreesWithTheFullComputation) {
  Rng rng(21);
  int interior = 0;
  for (int trial = 0; trial < 5000; ++trial) {
    const Vec3 p0 = randomPoint(rng), p1 = randomPoint(rng), q0 = randomPoint(rng), q1 = randomPoint(rng);
    const EdgeEdgeProximity full = edgeEdgeProximity(p0, p1, q0, q1);
    const std::optional<EdgeEdgeProximity> inside = edgeEdgeInteriorProximity(p0, p1, q0, q1);
    const bool expected = full.s > 0.0 && full.s < 1.0 && full.t > 0.0 && full.t < 1.0;
    ASSERT_EQ(inside.has_value(), expected) << "trial " << trial;
    if (!inside) continue;
    ++interior;
    EXPECT_NEAR(inside->distance, full.distance, 1e-14);
    EXPECT_NEAR(inside->s, full.s, 1e-14);
    EXPECT_NEAR(inside->t, full.t, 1e-14);
    EXPECT_LT((inside->normal - full.normal).norm(), 1e-12);
  }
  EXPECT_GT(interior, 500);  // both kinds occur
  EXPECT_LT(interior, 4500);
  // Parallel edges have no unique interior pair: none.
  EXPECT_FALSE(edgeEdgeInteriorProximity(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(0, 1, 0), Vec3(1, 1, 0)));
}

TEST(CollisionGeometry, EdgeEdgeKnownCases) {
  // Skew edges crossing above each other: the common perpendicular at their midpoints.
  EdgeEdgeProximity r = edgeEdgeProximity(Vec3(-1, 0, 1), Vec3(1, 0, 1), Vec3(0, -1, 0), Vec3(0, 1, 0));
  EXPECT_NEAR(r.distance, 1.0, 1e-15);
  EXPECT_NEAR(r.s, 0.5, 1e-15);
  EXPECT_NEAR(r.t, 0.5, 1e-15);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ(), 1e-15)) << "from the second edge towards the first";
  // The lines cross outside the edges: the closest points are an endpoint and its foot.
  r = edgeEdgeProximity(Vec3(2, 0, 1), Vec3(3, 0, 1), Vec3(0, -1, 0), Vec3(0, 1, 0));
  EXPECT_NEAR(r.distance, std::sqrt(5.0), 1e-15);
  EXPECT_EQ(r.s, 0.0);
  EXPECT_NEAR(r.t, 0.5, 1e-15);
  // Touching edges: distance 0 and the normal of both edges, u x v.
  r = edgeEdgeProximity(Vec3(-1, 0, 0), Vec3(1, 0, 0), Vec3(0, -1, 0), Vec3(0, 1, 0));
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_TRUE(r.normal.isApprox(Vec3::UnitZ(), 1e-15));
}

TEST(CollisionGeometry, EdgeEdgeHandlesParallelAndDegenerateEdges) {
  // Parallel and overlapping: every overlapping pair is closest, at the lines' distance.
  EdgeEdgeProximity r = edgeEdgeProximity(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0.5, 0), Vec3(3, 0.5, 0));
  EXPECT_NEAR(r.distance, 0.5, 1e-15);
  expectConsistent(r, Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0.5, 0), Vec3(3, 0.5, 0), "parallel");
  EXPECT_TRUE(r.normal.isApprox(-Vec3::UnitY(), 1e-15));
  // Parallel, apart along their line: endpoint to endpoint.
  r = edgeEdgeProximity(Vec3(0, 0, 0), Vec3(1, 0, 0), Vec3(5, 0, 4), Vec3(4, 0, 4));
  EXPECT_NEAR(r.distance, 5.0, 1e-15);
  EXPECT_EQ(r.s, 1.0);
  EXPECT_EQ(r.t, 1.0);
  // Collinear and overlapping: touching, with a unit normal perpendicular to the line.
  r = edgeEdgeProximity(Vec3(0, 0, 0), Vec3(2, 0, 0), Vec3(1, 0, 0), Vec3(3, 0, 0));
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-15);
  EXPECT_NEAR(r.normal.x(), 0.0, 1e-15);
  // Zero-length edges: a point against an edge, and two points (even coincident ones).
  r = edgeEdgeProximity(Vec3(0.5, 1, 0), Vec3(0.5, 1, 0), Vec3(0, 0, 0), Vec3(1, 0, 0));
  EXPECT_NEAR(r.distance, 1.0, 1e-15);
  EXPECT_NEAR(r.t, 0.5, 1e-15);
  r = edgeEdgeProximity(Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3), Vec3(1, 2, 3));
  EXPECT_EQ(r.distance, 0.0);
  EXPECT_TRUE(r.normal.allFinite());
  EXPECT_NEAR(r.normal.norm(), 1.0, 1e-15);
  // Nearly parallel edges (directions 1e-9 apart) against the sampled reference.
  Rng rng(13);
  for (int k = 0; k < 40; ++k) {
    const Vec3 p0 = randomPoint(rng), d = randomPoint(rng), q0 = p0 + 0.3 * randomPoint(rng);
    const Vec3 p1 = p0 + d, q1 = q0 + d + 1e-9 * randomPoint(rng);
    r = edgeEdgeProximity(p0, p1, q0, q1);
    const std::string what = "nearly parallel " + std::to_string(k);
    expectConsistent(r, p0, p1, q0, q1, what);
    EXPECT_NEAR(r.distance, sampledEdgeEdgeDistance(p0, p1, q0, q1), 1e-6 * r.distance) << what;
  }
}
