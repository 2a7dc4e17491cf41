// The bounding volume hierarchy (numerics/bvh.hpp) against brute force: rays find the nearest of
// a cloud of boxes (the same one every box tested in turn finds), box queries report exactly the
// overlapping boxes, and a ray walks only a few leaves: one that misses everything, with no bound
// on t (a camera ray into an empty sky), tests a handful of primitives, not all of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>
#include <random>
#include <vector>

#include "msim/numerics/bvh.hpp"

using namespace msim;
using namespace msim::numerics;

namespace {

// Small boxes scattered in the unit cube (seeded).
std::vector<Aabb> scatteredBoxes(int count) {
  std::mt19937 rng(11);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Aabb> boxes;
  for (int i = 0; i < count; ++i) {
    const Vec3 c(u(rng), u(rng), u(rng));
    Aabb b;
    b.grow(c - Vec3::Constant(0.005));
    b.grow(c + Vec3::Constant(0.005));
    boxes.push_back(b);
  }
  return boxes;
}

// Entry of the ray into b within [0, tMax], or infinity.
double slabEntry(const Aabb& b, const Vec3& o, const Vec3& d, double tMax) {
  double t0 = 0.0, t1 = tMax;
  for (int a = 0; a < 3; ++a) {
    double ta = (b.lo[a] - o[a]) / d[a], tb = (b.hi[a] - o[a]) / d[a];
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 <= t1 ? t0 : std::numeric_limits<double>::infinity();
}

}  // namespace

TEST(Bvh, RaysFindTheNearestBoxAndMissesTestFewPrimitives) {
  const std::vector<Aabb> boxes = scatteredBoxes(5000);
  const Bvh bvh(boxes);
  std::mt19937 rng(3);
  std::uniform_real_distribution<double> u(-1.0, 1.0);
  long missTests = 0;
  int misses = 0;
  for (int r = 0; r < 500; ++r) {
    const Vec3 origin(0.5 + u(rng), 0.5 + u(rng), 3.0);
    const Vec3 dir = Vec3(0.2 * u(rng), 0.2 * u(rng), -1.0).normalized();
    double nearest = std::numeric_limits<double>::infinity();
    int expected = -1;
    for (int i = 0; i < static_cast<int>(boxes.size()); ++i) {
      const double t = slabEntry(boxes[static_cast<std::size_t>(i)], origin, dir, nearest);
      if (t < nearest) nearest = t, expected = i;
    }
    double tMax = std::numeric_limits<double>::infinity();
    int found = -1;
    long tests = 0;
    bvh.traverse<false>(origin, dir, tMax, [&](int p, double& t) {
      ++tests;
      const double entry = slabEntry(boxes[static_cast<std::size_t>(p)], origin, dir, t);
      if (!(entry < t)) return false;
      t = entry;
      found = p;
      return true;
    });
    EXPECT_EQ(found, expected) << "ray " << r;
    if (expected < 0) {
      ++misses;
      missTests += tests;
    }
  }
  ASSERT_GT(misses, 50);
  testing::Test::RecordProperty("tests_per_missing_ray", std::to_string(double(missTests) / misses));
  // A missing ray walks the boxes near it only (all 5000 without the culling).
  EXPECT_LT(double(missTests) / misses, 20.0);
}

TEST(Bvh, BoxQueriesReportExactlyTheOverlappingBoxes) {
  const std::vector<Aabb> boxes = scatteredBoxes(2000);
  const Bvh bvh(boxes);
  Aabb query;
  query.grow(Vec3(0.3, 0.2, 0.4));
  query.grow(Vec3(0.5, 0.45, 0.6));
  std::vector<int> found;
  bvh.forEachOverlap(query, [&](int p) { found.push_back(p); });
  std::sort(found.begin(), found.end());
  std::vector<int> expected;
  for (int i = 0; i < static_cast<int>(boxes.size()); ++i)
    if (boxes[static_cast<std::size_t>(i)].overlaps(query)) expected.push_back(i);
  EXPECT_EQ(found, expected);
  EXPECT_GT(expected.size(), 10u);
}
