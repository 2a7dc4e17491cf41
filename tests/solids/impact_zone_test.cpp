// Rigid impact zones (Bridson, Fedkiw & Anderson 2002 sec. 7.4; Selle ch. 6.3 step C.6): a zone's
// new motion is rigid (distances kept to 1e-12), keeps the zone's linear momentum and starts with
// its angular momentum (I omega = L, the rotation recovered from the new positions by an
// independent fit), without NaNs when the inertia tensor is singular (colinear, coincident or two
// particles); pinned particles hold their zone; overlapping collisions merge into one zone.
#include <gtest/gtest.h>

#include <cmath>
#include <string>
#include <utility>
#include <vector>

#include <Eigen/Geometry>
#include <Eigen/SVD>

#include "msim/core/rng.hpp"
#include "msim/solids/collision/impact_zone.hpp"
#include "random_points.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

constexpr double kDt = 0.01;

struct Particles {
  std::vector<double> mass;
  std::vector<char> pinned;
  std::vector<Vec3> x0, x1;
};

Particles randomParticles(Rng& rng, int n) {
  Particles p;
  for (int i = 0; i < n; ++i) {
    p.mass.push_back(rng.uniform(0.5, 2.0));
    p.pinned.push_back(0);
    p.x0.push_back(randomVector(rng, 1.0));
    p.x1.push_back(p.x0.back() + kDt * randomVector(rng, 3.0));
  }
  return p;
}

// The zone's momentum and inertia, computed here from their definitions.
struct ZoneMomentum {
  double mass = 0.0;
  Vec3 centre = Vec3::Zero(), linear = Vec3::Zero(), angular = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
};

ZoneMomentum momentumOf(const Particles& p, const std::vector<Vec3>& x1) {
  ZoneMomentum z;
  for (std::size_t i = 0; i < p.mass.size(); ++i) {
    z.mass += p.mass[i];
    z.centre += p.mass[i] * p.x0[i];
    z.linear += p.mass[i] * (x1[i] - p.x0[i]) / kDt;
  }
  z.centre /= z.mass;
  for (std::size_t i = 0; i < p.mass.size(); ++i) {
    const Vec3 r = p.x0[i] - z.centre;
    z.angular += p.mass[i] * r.cross((x1[i] - p.x0[i]) / kDt);
    z.inertia += p.mass[i] * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  return z;
}

std::vector<int> allOf(const Particles& p) {
  std::vector<int> zone(p.mass.size());
  for (std::size_t i = 0; i < zone.size(); ++i) zone[i] = static_cast<int>(i);
  return zone;
}

// Every pairwise distance at the end equals the one at the start, to `tolerance` relative.
void expectDistancesKept(const Particles& p, const std::vector<Vec3>& x1, double tolerance, const std::string& what) {
  for (std::size_t i = 0; i < x1.size(); ++i) {
    ASSERT_TRUE(x1[i].allFinite()) << what;
    for (std::size_t j = i + 1; j < x1.size(); ++j) {
      const double before = (p.x0[i] - p.x0[j]).norm(), after = (x1[i] - x1[j]).norm();
      EXPECT_NEAR(after, before, tolerance * (1.0 + before)) << what << " pair " << i << "," << j;
    }
  }
}

// The rotation taking the start offsets to the end offsets (Kabsch: the SVD of their correlation).
Eigen::Matrix3d fittedRotation(const std::vector<Vec3>& from, const std::vector<Vec3>& to) {
  Eigen::Matrix3d correlation = Eigen::Matrix3d::Zero();
  for (std::size_t i = 0; i < from.size(); ++i) correlation += to[i] * from[i].transpose();
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(correlation, Eigen::ComputeFullU | Eigen::ComputeFullV);
  Eigen::Matrix3d fix = Eigen::Matrix3d::Identity();
  fix(2, 2) = (svd.matrixU() * svd.matrixV().transpose()).determinant() < 0.0 ? -1.0 : 1.0;
  return svd.matrixU() * fix * svd.matrixV().transpose();
}

}  // namespace

TEST(ImpactZone, RigidMotionKeepsMomentumAndDistances) {
  Rng rng(21);
  for (int k = 0; k < 50; ++k) {
    const Particles p = randomParticles(rng, 3 + k % 8);
    const std::string what = "zone " + std::to_string(k);
    const ZoneMomentum before = momentumOf(p, p.x1);
    std::vector<Vec3> x1 = p.x1;
    applyRigidImpactZone(allOf(p), p.mass, p.pinned, p.x0, x1, kDt);

    expectDistancesKept(p, x1, 1e-12, what);
    const ZoneMomentum after = momentumOf(p, x1);
    EXPECT_LT((after.linear - before.linear).norm(), 1e-12 * before.linear.norm()) << what;

    // The rotation, fitted to the new positions, turns at omega with I omega = L.
    std::vector<Vec3> from, to;
    const Vec3 centreAtEnd = before.centre + kDt * before.linear / before.mass;
    for (std::size_t i = 0; i < x1.size(); ++i) {
      from.push_back(p.x0[i] - before.centre);
      to.push_back(x1[i] - centreAtEnd);
    }
    const Eigen::Matrix3d rotation = fittedRotation(from, to);
    for (std::size_t i = 0; i < from.size(); ++i) EXPECT_LT((rotation * from[i] - to[i]).norm(), 1e-13) << what;
    const Eigen::AngleAxisd turn(rotation);
    const Vec3 omega = turn.angle() * turn.axis() / kDt;
    EXPECT_LT((before.inertia * omega - before.angular).norm(), 1e-12 * before.angular.norm()) << what;

    const RigidZoneMotion motion = rigidZoneMotion(allOf(p), p.mass, p.pinned, p.x0, p.x1, kDt);
    EXPECT_LT((before.inertia * motion.angularVelocity - before.angular).norm(), 1e-12 * before.angular.norm())
        << what;
    EXPECT_LT((motion.angularVelocity - omega).norm(), 1e-10 * omega.norm()) << what;
  }
}

TEST(ImpactZone, SingularInertiaGivesNoNaN) {
  Rng rng(23);
  const Vec3 direction = Vec3(1, 2, -2) / 3.0;
  for (int k = 0; k < 20; ++k) {
    // Colinear particles (no moment about their line), two particles, coincident particles.
    Particles colinear = randomParticles(rng, 4), two = randomParticles(rng, 2), coincident = randomParticles(rng, 3);
    for (std::size_t i = 0; i < 4; ++i) colinear.x0[i] = Vec3(0.1, 0.2, 0.3) + (0.25 * i - 0.4) * direction;
    const Vec3 common = randomVector(rng, 1.0);  // x_cm then differs from it by rounding
    for (std::size_t i = 0; i < 3; ++i) coincident.x0[i] = common;
    for (const auto& [p, name] : {std::pair{colinear, "colinear"}, std::pair{two, "two"},
                                  std::pair{coincident, "coincident"}}) {
      const std::string what = std::string(name) + " " + std::to_string(k);
      const ZoneMomentum before = momentumOf(p, p.x1);
      const RigidZoneMotion motion = rigidZoneMotion(allOf(p), p.mass, p.pinned, p.x0, p.x1, kDt);
      ASSERT_TRUE(motion.angularVelocity.allFinite()) << what;
      if (std::string(name) == "coincident") {
        // No spin at all (their L is the rounding of x_cm).
        EXPECT_EQ(motion.angularVelocity, Vec3::Zero()) << what;
      } else {
        // L has no component about the line, and omega none either: I omega = L.
        EXPECT_LT((before.inertia * motion.angularVelocity - before.angular).norm(), 1e-12 * before.angular.norm())
            << what;
        const Vec3 line = (p.x0[1] - p.x0[0]).normalized();
        EXPECT_LT(std::abs(motion.angularVelocity.dot(line)), 1e-9 * motion.angularVelocity.norm()) << what;
      }
      std::vector<Vec3> x1 = p.x1;
      applyRigidImpactZone(allOf(p), p.mass, p.pinned, p.x0, x1, kDt);
      expectDistancesKept(p, x1, 1e-12, what);
      EXPECT_LT((momentumOf(p, x1).linear - before.linear).norm(), 1e-12 * before.linear.norm()) << what;
    }
  }
  // A single particle keeps its own motion.
  Particles one = randomParticles(rng, 1);
  std::vector<Vec3> x1 = one.x1;
  applyRigidImpactZone(allOf(one), one.mass, one.pinned, one.x0, x1, kDt);
  EXPECT_LT((x1[0] - one.x1[0]).norm(), 1e-15);
}

TEST(ImpactZone, PinnedParticlesHoldTheirZone) {
  Rng rng(29);
  Particles p = randomParticles(rng, 5);
  // A still pin: the whole zone stays where it started.
  p.pinned[2] = 1;
  p.x1[2] = p.x0[2];
  std::vector<Vec3> x1 = p.x1;
  applyRigidImpactZone(allOf(p), p.mass, p.pinned, p.x0, x1, kDt);
  for (std::size_t i = 0; i < x1.size(); ++i) EXPECT_LT((x1[i] - p.x0[i]).norm(), 1e-15) << i;
  // Two pins moving together: the zone translates with them, and they keep their positions.
  p.pinned[4] = 1;
  const Vec3 shift(0.01, -0.02, 0.005);
  p.x1[2] = p.x0[2] + shift;
  p.x1[4] = p.x0[4] + shift;
  x1 = p.x1;
  applyRigidImpactZone(allOf(p), p.mass, p.pinned, p.x0, x1, kDt);
  for (std::size_t i = 0; i < x1.size(); ++i) EXPECT_LT((x1[i] - p.x0[i] - shift).norm(), 1e-15) << i;
  // Only the zone's particles move.
  p.pinned = {0, 0, 0, 0, 0};
  x1 = p.x1;
  applyRigidImpactZone(std::vector<int>{1, 3}, p.mass, p.pinned, p.x0, x1, kDt);
  for (const std::size_t i : {0u, 2u, 4u}) EXPECT_EQ(x1[i], p.x1[i]);
}

TEST(ImpactZone, OverlappingCollisionsMerge) {
  ImpactZones zones(30);
  EXPECT_TRUE(zones.zones().empty());
  zones.addCollision(std::vector<int>{0, 1, 2, 3});
  zones.addCollision(std::vector<int>{13, 12, 11, 10});
  zones.addCollision(std::vector<int>{22, 21, 20, 3});  // shares particle 3 with the first
  using Zones = std::vector<std::vector<int>>;
  EXPECT_EQ(zones.zones(), (Zones{{0, 1, 2, 3, 20, 21, 22}, {10, 11, 12, 13}}));
  zones.addCollision(std::vector<int>{25, 26, 27, 28});
  zones.addCollision(std::vector<int>{13, 5, 6, 0});  // joins the first two zones
  EXPECT_EQ(zones.zones(), (Zones{{0, 1, 2, 3, 5, 6, 10, 11, 12, 13, 20, 21, 22}, {25, 26, 27, 28}}));
}
