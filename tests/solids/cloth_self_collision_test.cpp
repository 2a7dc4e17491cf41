// Self-collisions of cloth (Selle ch. 6.2-6.4), judged by the exact triangle-triangle referee
// (collision/triangle_intersection.hpp), which shares no code with the collision handling:
//  * a point pushed through a triangle is pulled back, because the pair remembers its side
//    (ch. 6.4, Fig. 6.4), while a pair found afresh in the crossed state would push it on;
//  * the inelastic repulsion stops a pair's approach and keeps the total momentum;
//  * a cloth dropped edge-first onto a floor crumples onto itself with no intersection after any
//    outer step, while the same drop without the collision loop passes through itself;
//  * two sheets thrown into each other do not pass through and keep their total momentum.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <memory>
#include <random>

#include <Eigen/Geometry>

#include "msim/geometry/analytic_shapes.hpp"
#include "msim/solids/cloth_collision_loop.hpp"
#include "msim/solids/cloth_mesh.hpp"
#include "msim/solids/collision/triangle_intersection.hpp"
#include "msim/solids/newmark.hpp"
#include "floor_drop.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

// A triangle in the plane y = 0 and a point above it at height y.
struct PointOverTriangle {
  std::vector<Vec3> x{Vec3(0.0, 0.0, 0.0), Vec3(1.0, 0.0, 0.0), Vec3(0.0, 0.0, 1.0), Vec3(0.25, 0.0, 0.25)};
  std::vector<double> inverseMass{1.0, 1.0, 1.0, 1.0};
  CollisionPairs pairs{{{0, 2, 1}}, 4};  // a lone triangle: its only candidate pair is with point 3
  explicit PointOverTriangle(double y) { x[3][1] = y; }
};

Vec3 totalMomentum(const std::vector<Vec3>& v) {
  Vec3 sum = Vec3::Zero();
  for (const Vec3& u : v) sum += u;
  return sum;
}

}  // namespace

TEST(SelfRepulsion, PointPushedThroughIsPulledBack) {
  RepulsionSettings settings;
  settings.thickness = 0.01;
  settings.stiffness = 100.0;
  const double dt = 1e-3;
  PointOverTriangle scene(0.005);
  SelfRepulsion remembered(settings);
  remembered.findPairs(scene.pairs, scene.x, scene.x);  // the point's side: above
  scene.x[3][1] = -0.005;                                // pushed through
  std::vector<Vec3> v(4, Vec3::Zero());
  EXPECT_EQ(remembered.repelPositionVelocity(scene.x, v, scene.inverseMass, dt), 1);
  EXPECT_GT(v[3][1], 0.0) << "pulled back up";
  EXPECT_LT(v[0][1], 0.0);

  SelfRepulsion afresh(settings);
  afresh.findPairs(scene.pairs, scene.x, scene.x);  // found below: pushes it further down
  std::vector<Vec3> w(4, Vec3::Zero());
  afresh.repelPositionVelocity(scene.x, w, scene.inverseMass, dt);
  EXPECT_LT(w[3][1], 0.0);
}

TEST(SelfRepulsion, InelasticImpulseStopsTheApproachAndKeepsMomentum) {
  PointOverTriangle scene(0.004);
  SelfRepulsion repulsion;
  repulsion.findPairs(scene.pairs, scene.x, scene.x);
  std::vector<Vec3> v = {Vec3(0.1, 0.0, 0.0), Vec3(0.1, 0.2, 0.0), Vec3(0.1, 0.0, 0.0), Vec3(0.3, -1.0, 0.2)};
  const Vec3 before = totalMomentum(v);
  repulsion.repelEndVelocity(scene.x, v, scene.inverseMass);
  // The point sits over (0.25, 0.25): weights 1/2 on vertex 0 and 1/4 on the others.
  const Vec3 relative = v[3] - (0.5 * v[0] + 0.25 * v[1] + 0.25 * v[2]);
  EXPECT_NEAR(relative[1], 0.0, 1e-12) << "approach stopped (it was -1.05 m/s)";
  EXPECT_LT((totalMomentum(v) - before).norm(), 1e-12);
  // Coulomb friction: mu times the 1.05 m/s of normal speed removed (0.315) exceeds the 0.283
  // m/s of sliding, which stops.
  EXPECT_NEAR(std::hypot(relative[0], relative[2]), 0.0, 1e-12);
}

// A gathering after only some particles moved re-examines only their pairs (self_repulsion.hpp):
// its impulses must equal those of a repulsion that examines every pair at the new positions.
TEST(SelfRepulsion, PairsOfParticlesThatStayedKeepWhatWasFound) {
  // Two 12 x 12 sheets 0.4 thicknesses apart, jittered: hundreds of point-face and edge pairs.
  const double thickness = 0.01;
  TriangleMesh lower = clothPatch(Vec3::Zero(), Vec3(0.2, 0.0, 0.0), Vec3(0.0, 0.0, 0.2), 12, 12);
  const TriangleMesh upper = clothPatch(Vec3(0.004, 0.4 * thickness, 0.003), Vec3(0.2, 0.0, 0.0), Vec3(0.0, 0.0, 0.2), 12, 12);
  const int offset = static_cast<int>(lower.vertices.size());
  lower.vertices.insert(lower.vertices.end(), upper.vertices.begin(), upper.vertices.end());
  for (auto t : upper.triangles) lower.triangles.push_back({t[0] + offset, t[1] + offset, t[2] + offset});
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> jitter(-0.2 * thickness, 0.2 * thickness);
  std::vector<Vec3> start = lower.vertices;
  for (Vec3& x : start) x += Vec3(jitter(rng), 0.3 * jitter(rng), jitter(rng));
  std::vector<Vec3> later = start;  // every seventh particle moves on
  for (std::size_t v = 0; v < later.size(); v += 7) later[v] += Vec3(jitter(rng), jitter(rng), jitter(rng));

  RepulsionSettings settings;
  settings.thickness = thickness;
  settings.stiffness = 50.0;
  CollisionPairs pairs(lower.triangles, start.size());
  const std::vector<double> inverseMass(start.size(), 1e3);
  std::uniform_real_distribution<double> speed(-0.05, 0.05);
  std::vector<Vec3> v0(start.size());
  for (Vec3& u : v0) u = Vec3(speed(rng), speed(rng), speed(rng));

  SelfRepulsion incremental(settings), afresh(settings);
  incremental.findPairs(pairs, start, start);
  std::vector<Vec3> first = v0;
  const int atStart = incremental.repelPositionVelocity(start, first, inverseMass, 1e-3);
  ASSERT_GT(atStart, 100);
  std::vector<Vec3> viaIncremental = v0, viaAfresh = v0;
  const int found = incremental.repelPositionVelocity(later, viaIncremental, inverseMass, 1e-3);
  afresh.findPairs(pairs, start, start);
  EXPECT_EQ(found, afresh.repelPositionVelocity(later, viaAfresh, inverseMass, 1e-3));
  EXPECT_NE(found, atStart) << "the moved particles changed the contacts";
  for (std::size_t p = 0; p < v0.size(); ++p) ASSERT_EQ(viaIncremental[p], viaAfresh[p]) << "particle " << p;
}

namespace {

struct Drop {
  std::size_t worstSelf = 0;  // most self-intersecting triangle pairs after any outer step
  double lowest = 1.0;        // lowest vertex height over the run [m]
  int repulsions = 0, collisions = 0;
};

// The floor drop (floor_drop.hpp) of 24 x 24 quads in outer steps of 1/100 s, for `seconds`.
Drop dropOntoFloor(bool collisions, double seconds) {
  FloorDrop scene = floorDrop(24);
  const TriangleMesh& mesh = scene.mesh;
  MassSpringSystem& system = scene.system;
  const BodyContact& floor = scene.floor;
  ClothCollisionLoop loop(mesh.triangles, system.size(), scene.newmark, scene.settings);
  NewmarkStepper plain(scene.newmark);
  const double T = 0.01;
  Drop drop;
  for (int step = 0; step < static_cast<int>(seconds / T + 0.5); ++step) {
    if (collisions) {
      const ClothCollisionStats s = loop.step(system, T, [&] { return T / 8.0; }, &floor);
      drop.repulsions += s.repulsions;
      drop.collisions += s.collisions.collisions;
      EXPECT_EQ(s.collisions.unresolved, 0) << "step " << step;
    } else {
      for (int k = 0; k < 8; ++k) plain.step(system, T / 8.0, &floor);
    }
    drop.worstSelf = std::max(drop.worstSelf, countSelfIntersections(system.x, mesh.triangles));
    for (const Vec3& x : system.x) drop.lowest = std::min(drop.lowest, x[1]);
  }
  return drop;
}

}  // namespace

TEST(ClothCollisionLoop, ClothCrumpledOnAFloorNeverPassesThroughItself) {
  const Drop with = dropOntoFloor(true, 1.2);
  EXPECT_EQ(with.worstSelf, 0u);
  EXPECT_GE(with.lowest, -1e-9) << "below the floor";
  EXPECT_GT(with.repulsions, 0) << "the cloth met itself";
  RecordProperty("repulsions", with.repulsions);
  RecordProperty("collisions", with.collisions);
  const Drop without = dropOntoFloor(false, 1.2);
  EXPECT_GT(without.worstSelf, 0u) << "the drop is not a test of self-collisions";
}
