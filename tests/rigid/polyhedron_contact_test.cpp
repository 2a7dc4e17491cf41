// Box and convex-mesh contacts: the separating axis test and clipped manifold against analytic
// geometry, and stacking/sliding against statics (force balance, Coulomb's tan(angle) = mu).
#include "msim/rigid/world.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <numbers>

#include "msim/rigid/mass_properties.hpp"
#include "rotations.hpp"
#include "test_meshes.hpp"

namespace msim::rigid {
namespace {

constexpr double kGravity = 9.81;

RigidBody placed(Shape shape, const Vec3& position, const Eigen::Quaterniond& orientation) {
  RigidBody b = RigidBody::fromDensity(std::move(shape), 1000.0);
  b.position = position;
  b.orientation = orientation;
  return b;
}

using testing::about;

std::vector<Contact> contactsOf(const RigidBody& a, const RigidBody& b, double margin = 1e-6) {
  std::vector<Contact> out;
  collidePair(a, 0, b, 1, margin, out);
  return out;
}

TEST(RigidPolyhedronContact, EdgeEdgeCrossingGivesAnalyticDepthAndNormal) {
  // Lower cube (side 1) turned 45 deg about y: its top is the edge {x = 0, z = sqrt(2)/2}, along
  // y. Upper cube turned 45 deg about x: its bottom is an edge along x at y = -0.05, height
  // z_a - sqrt(2)/2. The edges cross at (0, -0.05, sqrt(2)/2) with penetration d along +z.
  const double d = 0.05, half = std::sqrt(0.5);
  const RigidBody lower = placed(Box{}, Vec3::Zero(), about(std::numbers::pi / 4, Vec3::UnitY()));
  const RigidBody upper = placed(Box{}, Vec3(0.1, -0.05, 2 * half - d),
                                 about(std::numbers::pi / 4, Vec3::UnitX()));
  const std::vector<Contact> c = contactsOf(upper, lower);
  ASSERT_EQ(c.size(), 1u);
  EXPECT_NEAR(c[0].depth, d, 1e-12);
  EXPECT_LE((c[0].normal - Vec3::UnitZ()).norm(), 1e-12);
  EXPECT_LE((c[0].point - Vec3(0, -0.05, half)).norm(), 1e-12);
  // Swapping the bodies flips the normal and moves the point onto the other edge.
  const std::vector<Contact> s = contactsOf(lower, upper);
  ASSERT_EQ(s.size(), 1u);
  EXPECT_NEAR(s[0].depth, d, 1e-12);
  EXPECT_LE((s[0].normal + Vec3::UnitZ()).norm(), 1e-12);
  EXPECT_LE((s[0].point - Vec3(0, -0.05, half - d)).norm(), 1e-12);
  // Lifted clear of the margin: no contact.
  RigidBody apart = upper;
  apart.position.z() += 2 * d;
  EXPECT_TRUE(contactsOf(apart, lower).empty());
}

TEST(RigidPolyhedronContact, MeshCubeCollidesLikeBox) {
  // A cuboid turned 30 deg about z and tilted 0.6 deg about a generic axis (so no two points tie
  // in the reduction), sunk into a slab: its corners overhang the slab, so the clipped manifold
  // has more than 4 candidate points and the reduction is exercised too.
  const Vec3 ha(0.45, 0.4, 0.25), hb(0.5, 0.5, 0.1);
  const Eigen::Quaterniond qa = about(0.52, Vec3::UnitZ()) * about(0.01, Vec3(1, 0.3, 0));
  const Vec3 xa(0.02, 0.01, 0.1 + 0.25 - 0.01);
  const Eigen::Quaterniond qb = about(0.1, Vec3(1, 2, 3));
  const Shape meshA = makeConvexMesh(testing::boxMesh(-ha, ha));
  const Shape meshB = makeConvexMesh(testing::boxMesh(-hb, hb));
  auto sorted = [](std::vector<Contact> c) {
    std::sort(c.begin(), c.end(), [](const Contact& p, const Contact& q) {
      return std::lexicographical_compare(p.point.data(), p.point.data() + 3, q.point.data(),
                                          q.point.data() + 3);
    });
    return c;
  };
  const auto reference = sorted(contactsOf(placed(Box{ha}, qb * xa, qb * qa),
                                           placed(Box{hb}, Vec3::Zero(), qb)));
  ASSERT_GE(reference.size(), 3u);
  ASSERT_LE(reference.size(), 4u);
  const std::pair<Shape, Shape> variants[] = {{meshA, Box{hb}}, {Box{ha}, meshB}, {meshA, meshB}};
  for (const auto& [a, b] : variants) {
    const auto got = sorted(contactsOf(placed(a, qb * xa, qb * qa), placed(b, Vec3::Zero(), qb)));
    ASSERT_EQ(got.size(), reference.size());
    for (std::size_t k = 0; k < got.size(); ++k) {
      EXPECT_LE((got[k].point - reference[k].point).norm(), 1e-12);
      EXPECT_LE((got[k].normal - reference[k].normal).norm(), 1e-12);
      EXPECT_NEAR(got[k].depth, reference[k].depth, 1e-12);
    }
  }
  std::printf("mesh cube vs box: %zu contacts, depths", reference.size());
  for (const Contact& c : reference) std::printf(" %.5f", c.depth);
  std::printf("\n");
}

TEST(RigidPolyhedronContact, SphereOnMeshMatchesSphereOnBox) {
  const Vec3 h(0.4, 0.3, 0.2);
  const Eigen::Quaterniond q = about(0.7, Vec3(1, -1, 2));
  const Shape mesh = makeConvexMesh(testing::boxMesh(-h, h));
  // Outside near a corner, outside over a face, and inside (pushed out through the nearest face).
  for (const Vec3& local : {Vec3(0.45, 0.33, 0.22), Vec3(0.1, 0.0, 0.28), Vec3(0.1, 0.25, 0.05)}) {
    const RigidBody ball = placed(Sphere{0.1}, Vec3(1, 2, 3) + q * local, Eigen::Quaterniond::Identity());
    const auto ref = contactsOf(ball, placed(Box{h}, Vec3(1, 2, 3), q));
    const auto got = contactsOf(ball, placed(mesh, Vec3(1, 2, 3), q));
    ASSERT_EQ(ref.size(), 1u);
    ASSERT_EQ(got.size(), 1u);
    EXPECT_LE((got[0].point - ref[0].point).norm(), 1e-12);
    EXPECT_LE((got[0].normal - ref[0].normal).norm(), 1e-12);
    EXPECT_NEAR(got[0].depth, ref[0].depth, 1e-12);
  }
}

TEST(RigidPolyhedronContact, StackOfThreeBoxesStaysStacked) {
  // Each step gravity changes a box's vertical velocity by -g dt and its contacts by the rest; a
  // box that keeps |v_z| << g dt therefore has contact impulses that carry the weight above it.
  World w;
  w.addPlane(Plane{Vec3::UnitZ(), 0.0, Material{0.5, 0.0}});
  const double h = 0.25, dt = 1e-3;
  std::vector<Vec3> start;
  for (int k = 0; k < 3; ++k) {
    RigidBody b = RigidBody::fromDensity(Box{Vec3::Constant(h)}, 500.0);
    b.position = Vec3(0.01 * k, -0.02 * k, h + 2 * h * k);
    start.push_back(b.position);
    w.addBody(b);
  }
  double maxVertical = 0.0;
  for (int step = 0; step < 2000; ++step) {
    w.step(dt);
    if (step >= 1000)
      for (const RigidBody& b : w.bodies())
        maxVertical = std::max(maxVertical, std::abs(b.velocity.z()));
  }
  double drift = 0.0, tilt = 0.0, yaw = 0.0;
  for (int k = 0; k < 3; ++k) {
    const RigidBody& b = w.body(k);
    drift = std::max(drift, (b.position - start[k]).norm());
    tilt = std::max(tilt, std::acos(std::min(1.0, (b.orientation * Vec3::UnitZ()).z())));
    yaw = std::max(yaw, std::abs(b.angularVelocity.z()));
  }
  std::printf("box stack, 2 s: drift %.3g m, tilt %.3g rad, max |v_z| in 2nd second %.3g m/s "
              "(g dt = %.3g m/s), yaw rate %.3g rad/s\n", drift, tilt, maxVertical, kGravity * dt, yaw);
  EXPECT_LT(drift, 1e-3);
  EXPECT_LT(tilt, 1e-3);
  EXPECT_LT(maxVertical, 0.01 * kGravity * dt);
}

// Box of side 0.2 dropped 1 mm onto a static slab tilted by `angle` about y; returns the speed
// down the slope at t = 1 s and at t = 0.5 s.
std::pair<double, double> slideOnSlope(double angle, double mu) {
  World w;
  const Eigen::Quaterniond tilt = about(angle, Vec3::UnitY());
  const int slab = w.addBody(RigidBody::makeStatic(Box{Vec3(3.0, 1.0, 0.25)}));
  w.body(slab).orientation = tilt;
  RigidBody box = RigidBody::fromDensity(Box{Vec3::Constant(0.1)}, 800.0);
  box.orientation = tilt;
  box.position = tilt * Vec3(0, 0, 0.25 + 0.1 + 1e-3);
  const int i = w.addBody(box);
  w.setPairFriction(i, slab, mu);
  const Vec3 down = tilt * Vec3::UnitX();  // the slab's x axis descends for angle > 0
  double half = 0.0;
  for (int k = 1; k <= 1000; ++k) {
    w.step(1e-3);
    if (k == 500) half = w.body(i).velocity.dot(down);
  }
  return {w.body(i).velocity.dot(down), half};
}

TEST(RigidPolyhedronContact, BoxOnSlopeSlidesIffTangentExceedsFriction) {
  const double mu = 0.5, critical = std::atan(mu), delta = 3.0 * std::numbers::pi / 180.0;
  const double stuckSpeed = slideOnSlope(critical - delta, mu).first;
  const auto [slideSpeed, slideHalf] = slideOnSlope(critical + delta, mu);
  const double theta = critical + delta;
  const double a = kGravity * (std::sin(theta) - mu * std::cos(theta));  // Coulomb sliding
  std::printf("slope mu = %.2f: at %.2f deg speed %.3g m/s; at %.2f deg acceleration %.4f m/s^2 "
              "(expected %.4f)\n", mu, (critical - delta) * 180 / std::numbers::pi, stuckSpeed,
              theta * 180 / std::numbers::pi, (slideSpeed - slideHalf) / 0.5, a);
  EXPECT_LT(std::abs(stuckSpeed), 1e-4);
  EXPECT_NEAR((slideSpeed - slideHalf) / 0.5, a, 0.02 * a);
}

}  // namespace
}  // namespace msim::rigid
