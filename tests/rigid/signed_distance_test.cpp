// Signed distance in the body frame against closed forms: sphere, box (face, edge and corner
// regions, inside), a mesh cube (same values as the box) and a compound (minimum over parts).
#include "msim/rigid/shapes.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "msim/rigid/mass_properties.hpp"
#include "test_meshes.hpp"

namespace msim::rigid {
namespace {

TEST(RigidSignedDistance, SphereIsDistanceToCentreMinusRadius) {
  const Shape s = Sphere{0.5};
  EXPECT_NEAR(signedDistance(s, Vec3(1, 0, 0)), 0.5, 1e-15);
  EXPECT_NEAR(signedDistance(s, Vec3(0, 0.2, 0)), -0.3, 1e-15);
  EXPECT_NEAR(signedDistance(s, Vec3(0.3, -0.4, 1.2)), 1.3 - 0.5, 1e-15);
  EXPECT_NEAR(signedDistance(s, Vec3::Zero()), -0.5, 1e-15);
}

// Box with half extents (0.5, 1, 1.5): points and their exact distances.
struct Probe {
  Vec3 p;
  double d;
};
const Probe kBoxProbes[] = {
    {Vec3(1.5, 2.0, 2.5), std::sqrt(3.0)},     // corner region: distance to (0.5, 1, 1.5)
    {Vec3(1.0, 2.0, 0.0), std::sqrt(1.25)},    // edge region
    {Vec3(0.7, 0.0, 0.0), 0.2},                // face region
    {Vec3(0.1, 0.2, 0.3), -0.4},               // inside: nearest face x = 0.5
    {Vec3(-0.2, -0.9, 1.0), -0.1},             // inside: nearest face y = -1
    {Vec3(0.5, 0.3, -1.5), 0.0},               // on an edge
};

TEST(RigidSignedDistance, BoxIsExactInEveryRegion) {
  const Shape box = Box{Vec3(0.5, 1.0, 1.5)};
  for (const Probe& q : kBoxProbes) EXPECT_NEAR(signedDistance(box, q.p), q.d, 1e-14) << q.p.transpose();
  // The distance-only path agrees with the closest point the contacts use.
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      for (int k = -3; k <= 3; ++k) {
        const Vec3 p(0.31 * i, 0.57 * j, 0.83 * k);
        EXPECT_EQ(signedDistance(box, p), closestSurfacePoint(std::get<Box>(box), p).distance) << p.transpose();
      }
}

TEST(RigidSignedDistance, MeshCubeMatchesBox) {
  const Vec3 h(0.5, 1.0, 1.5);
  const Shape mesh = makeConvexMesh(testing::boxMesh(-h, h));
  const Shape box = Box{h};
  for (const Probe& q : kBoxProbes) EXPECT_NEAR(signedDistance(mesh, q.p), q.d, 1e-14) << q.p.transpose();
  for (int i = -3; i <= 3; ++i)
    for (int j = -3; j <= 3; ++j)
      for (int k = -3; k <= 3; ++k) {
        const Vec3 p(0.31 * i, 0.57 * j, 0.83 * k);
        EXPECT_NEAR(signedDistance(mesh, p), signedDistance(box, p), 1e-14) << p.transpose();
      }
}

TEST(RigidSignedDistance, CompoundIsMinimumOverParts) {
  // Two unit spheres 3 apart along x (offsets +-1.5 once centred), the right one turned.
  const Compound c = makeCompound({{Sphere{1.0}, Vec3(0, 0, 0), Eigen::Quaterniond::Identity()},
                                   {Sphere{1.0}, Vec3(3, 0, 0), Eigen::Quaterniond(0, 0, 1, 0)}});
  const Shape s = c;
  EXPECT_NEAR(signedDistance(s, Vec3(0, 0, 0)), 0.5, 1e-14);   // midway: 1.5 - 1 to either
  EXPECT_NEAR(signedDistance(s, Vec3(1.5, 0, 0)), -1.0, 1e-14);  // right centre
  EXPECT_NEAR(signedDistance(s, Vec3(-1.5, 0, 3)), 2.0, 1e-14);
}

TEST(RigidOrientedBounds, TurnedBoxAndCompoundAgainstClosedForms) {
  // A 1 x 2 x 3 box turned 90 degrees about z swaps its x and y extents; turned 45 degrees its x
  // extent is (0.5 + 1) / sqrt(2).
  const Shape box = Box{Vec3(0.5, 1.0, 1.5)};
  const Eigen::Quaterniond quarter(Eigen::AngleAxisd(0.5 * M_PI, Vec3::UnitZ()));
  const Eigen::AlignedBox3d b = orientedBounds(box, quarter);
  EXPECT_TRUE(b.max().isApprox(Vec3(1.0, 0.5, 1.5), 1e-14)) << b.max().transpose();
  EXPECT_TRUE(b.min().isApprox(-Vec3(1.0, 0.5, 1.5), 1e-14)) << b.min().transpose();
  const Eigen::Quaterniond eighth(Eigen::AngleAxisd(0.25 * M_PI, Vec3::UnitZ()));
  EXPECT_NEAR(orientedBounds(box, eighth).max().x(), 1.5 / std::sqrt(2.0), 1e-14);
  // Two unit spheres 3 apart along x (offsets +-1.5 once centred), the pair turned 90 degrees
  // about z: they now lie along y.
  const Shape pair = makeCompound({{Sphere{1.0}, Vec3(0, 0, 0), Eigen::Quaterniond::Identity()},
                                   {Sphere{1.0}, Vec3(3, 0, 0), Eigen::Quaterniond::Identity()}});
  const Eigen::AlignedBox3d p = orientedBounds(pair, quarter);
  EXPECT_TRUE(p.max().isApprox(Vec3(1.0, 2.5, 1.0), 1e-14)) << p.max().transpose();
  EXPECT_TRUE(p.min().isApprox(Vec3(-1.0, -2.5, -1.0), 1e-14)) << p.min().transpose();
  // Never larger than the bounding sphere's cube.
  EXPECT_LE(p.max().maxCoeff(), boundingRadius(pair) + 1e-14);
}

}  // namespace
}  // namespace msim::rigid
