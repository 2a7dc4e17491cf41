// Free-area fractions (Narain 2011, ch. 4.4.3): exact polygon and disc coverage against closed
// forms (half cell, polygon area, pi r^2) and brute-force sampling, clamping of overlaps, errors.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <vector>

#include "msim/core/error.hpp"
#include "msim/crowd/free_area.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

double coveredSum(const FreeArea& fa) {
  double s = 0.0;
  const double cellArea = fa.grid().dx * fa.grid().dx;
  for (float f : fa.fraction().data()) s += (1.0 - f) * cellArea;
  return s;
}

// Midpoint-rule area of the points of [lo, hi] for which inside() holds, n x n samples.
template <typename Inside>
double sampledArea(const Vec2& lo, const Vec2& hi, int n, const Inside& inside) {
  const Vec2 h = (hi - lo) / n;
  int count = 0;
  for (int j = 0; j < n; ++j)
    for (int i = 0; i < n; ++i) count += inside(lo + Vec2((i + 0.5) * h.x(), (j + 0.5) * h.y()));
  return count * h.x() * h.y();
}

}  // namespace

TEST(FreeArea, HalfCoveredCellIsExactlyHalf) {
  FreeArea fa(GridSpec<2>(Vec2(0, 0), 1.0, IVec2(4, 4)));
  fa.addStaticObstacle(rectangle(Vec2(1.0, 1.0), Vec2(1.5, 2.0)));
  EXPECT_EQ(fa.fraction()(IVec2(1, 1)), 0.5f);
  double others = 0.0;
  for (std::size_t i = 0; i < fa.fraction().count(); ++i)
    if (i != fa.fraction().index(IVec2(1, 1))) others += fa.fraction()[i];
  EXPECT_EQ(others, 15.0);
}

TEST(FreeArea, CoveredAreasOfAConcavePolygonSumToItsArea) {
  // A clockwise, concave "U" spanning many cells of an offset grid with dx = 0.7.
  Polygon u{{Vec2(1.1, 1.3), Vec2(1.9, 6.2), Vec2(2.8, 6.0), Vec2(3.0, 2.4), Vec2(4.9, 2.2), Vec2(5.3, 6.6),
             Vec2(6.1, 6.4), Vec2(5.7, 1.05)}};
  std::reverse(u.vertices.begin(), u.vertices.end());
  FreeArea fa(GridSpec<2>(Vec2(0.3, 0.2), 0.7, IVec2(11, 11)));
  fa.addStaticObstacle(u);
  double staticSum = 0.0;
  for (double c : fa.staticCoverage().data()) staticSum += c;
  EXPECT_NEAR(staticSum, std::abs(signedArea(u)), 1e-12 * std::abs(signedArea(u)));
  // Per cell against sampling, in a cell the notch cuts.
  const Vec2 lo(0.3 + 0.7 * 4, 0.2 + 0.7 * 3), hi = lo + Vec2(0.7, 0.7);
  const double sampled = sampledArea(lo, hi, 1000, [&](const Vec2& x) { return contains(u, x); });
  EXPECT_NEAR(clippedArea(u, lo, hi), sampled, 2e-3 * 0.49);
  EXPECT_GT(sampled, 0.0);
  EXPECT_LT(sampled, 0.49);
}

TEST(FreeArea, DiscAreaIsExact) {
  const Vec2 c(2.37, 3.61);
  const double r = 0.83;
  EXPECT_NEAR(discRectangleArea(c, r, Vec2(0, 0), Vec2(10, 10)), std::numbers::pi * r * r, 1e-14);
  // A quadrant: the rectangle's corner at the centre.
  EXPECT_NEAR(discRectangleArea(c, r, c, c + Vec2(5, 5)), std::numbers::pi * r * r / 4, 1e-14);
  // A generic cut against sampling.
  const Vec2 lo(2.0, 3.3), hi(2.6, 4.7);
  const double sampled =
      sampledArea(lo, hi, 2000, [&](const Vec2& x) { return (x - c).squaredNorm() < r * r; });
  EXPECT_NEAR(discRectangleArea(c, r, lo, hi), sampled, 1e-4);
  // Per step discs spread over several cells sum to pi r^2.
  FreeArea fa(GridSpec<2>(Vec2(0, 0), 0.5, IVec2(12, 12)));
  const std::vector<Vec2f> centres{Vec2f(2.37f, 3.61f), Vec2f(4.1f, 1.2f)};
  const std::vector<float> radii{0.83f, 0.3f};
  fa.update(centres, radii);
  const double expected = std::numbers::pi * (0.83 * 0.83 + 0.3 * 0.3);
  EXPECT_NEAR(coveredSum(fa), expected, 1e-5);  // fractions are float
}

TEST(FreeArea, OverlapsAreClampedAndDiscsDoNotAccumulateOverSteps) {
  FreeArea fa(GridSpec<2>(Vec2(0, 0), 1.0, IVec2(3, 3)));
  fa.addStaticObstacle(rectangle(Vec2(1, 1), Vec2(2, 2)));
  fa.addStaticObstacle(rectangle(Vec2(1, 1), Vec2(1.5, 2)));  // overlaps the first
  EXPECT_EQ(fa.fraction()(IVec2(1, 1)), 0.0f);
  const std::vector<Vec2f> centre{Vec2f(0.5f, 0.5f)};
  const std::vector<float> radius{2.0f};  // covers cells (0,0), (1,0), (0,1) fully
  fa.update(centre, radius);
  EXPECT_EQ(fa.fraction()(IVec2(0, 0)), 0.0f);
  EXPECT_EQ(fa.fraction()(IVec2(1, 1)), 0.0f);
  const std::vector<float> none{0.0f};
  fa.update(centre, none);  // the disc of the last step is gone, the static part stays
  EXPECT_EQ(fa.fraction()(IVec2(0, 0)), 1.0f);
  EXPECT_EQ(fa.fraction()(IVec2(1, 1)), 0.0f);
}

TEST(FreeArea, RejectsBadObstacles) {
  FreeArea fa(GridSpec<2>(Vec2(0, 0), 1.0, IVec2(3, 3)));
  EXPECT_THROW(fa.addStaticObstacle(Polygon{{Vec2(0, 0), Vec2(1, 1)}}), InputError);
  EXPECT_THROW(fa.addStaticObstacle(Polygon{{Vec2(0, 0), Vec2(1, NAN), Vec2(0, 1)}}), InputError);
  const std::vector<Vec2f> centre{Vec2f(NAN, 0.5f)};
  const std::vector<float> radius{1.0f};
  EXPECT_THROW(fa.update(centre, radius), InputError);
  const std::vector<float> two{1.0f, 1.0f};
  EXPECT_THROW(fa.update(centre, two), InputError);
}
