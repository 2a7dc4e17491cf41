// Voronoi density (Steffen & Seyfried 2010) against lattices, whose cells are known exactly, and
// clipped cells whose areas follow from elementary geometry.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <vector>

#include "msim/crowd/voronoi_density.hpp"

namespace msim::crowd {
namespace {

constexpr double kPi = std::numbers::pi;

VoronoiOptions cutoff(double radius, std::optional<Vec2> lo = {}, std::optional<Vec2> hi = {}) {
  VoronoiOptions o;
  o.cutoffRadius = radius;
  o.domainLo = lo;
  o.domainHi = hi;
  return o;
}

// Agents of a lattice with rows `h` apart and spacing `a` along a row, odd rows shifted by
// `shift`, inside [0, nx a] x [0, ny h].
std::vector<Vec2f> lattice(int nx, int ny, float a, float h, float shift) {
  std::vector<Vec2f> p;
  for (int j = 0; j < ny; ++j)
    for (int i = 0; i < nx; ++i) p.emplace_back((i + 0.25f) * a + (j % 2) * shift, (j + 0.5f) * h);
  return p;
}

bool interior(const Vec2f& p, float lo, float hiX, float hiY, float margin) {
  return p.x() > lo + margin && p.y() > lo + margin && p.x() < hiX - margin && p.y() < hiY - margin;
}

TEST(VoronoiDensity, TriangularLatticeInteriorIsTheCloselyPackedDensity) {
  // Floats cannot hold a sqrt(3)/2 row spacing, so the lattice is centred rectangular with the row
  // spacing h rounded to 18 binary places (every position is then exact in float); its cell area
  // is exactly a h, and a h = sqrt(3)/2 a^2 to 1e-5.
  const float a = 0.5f;
  const float h = static_cast<float>(std::round(0.5 * std::sqrt(3.0) * a * 262144.0) / 262144.0);
  const auto p = lattice(20, 20, a, h, 0.5f * a);
  const VoronoiCells cells = voronoiCells(p, cutoff(a));
  const std::vector<double> rho = voronoiDensity(cells);
  int checked = 0;
  for (std::size_t i = 0; i < p.size(); ++i) {
    if (!interior(p[i], 0.0f, 20 * a, 20 * h, 2 * a)) continue;
    EXPECT_NEAR(rho[i], 1.0 / (double(a) * h), 1e-9 * rho[i]) << i;
    EXPECT_NEAR(rho[i], 2.0 / (std::sqrt(3.0) * a * a), 1e-5 * rho[i]) << i;
    ++checked;
  }
  EXPECT_GT(checked, 200);
}

TEST(VoronoiDensity, SquareLatticeInteriorIsOneOverASquared) {
  const float a = 0.5f;
  const auto p = lattice(16, 16, a, a, 0.0f);
  const std::vector<double> rho = voronoiDensity(voronoiCells(p, cutoff(a)));
  for (std::size_t i = 0; i < p.size(); ++i)
    if (interior(p[i], 0.0f, 16 * a, 16 * a, 1.5f * a)) {
      EXPECT_NEAR(rho[i], 4.0, 1e-9) << i;
    }
}

TEST(VoronoiDensity, IsolatedAgentOwnsTheCutoffDisc) {
  const std::vector<Vec2f> p = {Vec2f(3.0f, 4.0f)};
  const VoronoiCells cells = voronoiCells(p, cutoff(2.0));
  EXPECT_NEAR(cells.area(0), kPi * 4.0, 1e-12);
  EXPECT_NEAR(voronoiDensity(cells)[0], 1.0 / (kPi * 4.0), 1e-12);
}

TEST(VoronoiDensity, AgentInTheCornerOfTheDomainGetsAQuarterDisc) {
  const std::vector<Vec2f> p = {Vec2f(0.0f, 0.0f)};
  const VoronoiCells cells = voronoiCells(p, cutoff(1.0, Vec2(0, 0), Vec2(10, 10)));
  EXPECT_NEAR(cells.area(0), kPi / 4.0, 1e-12);
}

TEST(VoronoiDensity, TwoAgentsSplitTheDomainAtTheirBisector) {
  // The bisector x + y = 0 halves the 10 x 10 box, and R = 10 reaches all of each half.
  const std::vector<Vec2f> p = {Vec2f(-0.5f, -0.5f), Vec2f(0.5f, 0.5f)};
  const VoronoiCells cells = voronoiCells(p, cutoff(10.0, Vec2(-5, -5), Vec2(5, 5)));
  EXPECT_NEAR(cells.area(0), 50.0, 1e-9);
  EXPECT_NEAR(cells.area(1), 50.0, 1e-9);
}

TEST(VoronoiDensity, CollinearAgentsGetStripsOfTheDisc) {
  // The middle one of three agents 1 m apart owns the strip |x| <= 0.5 of its unit disc:
  // 2 (c sqrt(1 - c^2) + asin c) with c = 0.5.
  const std::vector<Vec2f> p = {Vec2f(-1.0f, 0.0f), Vec2f(0.0f, 0.0f), Vec2f(1.0f, 0.0f)};
  const VoronoiCells cells = voronoiCells(p, cutoff(1.0));
  EXPECT_NEAR(cells.area(1), 2.0 * (0.5 * std::sqrt(0.75) + std::asin(0.5)), 1e-12);
}

TEST(VoronoiDensity, AgentsAtOnePositionShareTheirCell) {
  const std::vector<Vec2f> p = {Vec2f(1.0f, 1.0f), Vec2f(1.0f, 1.0f)};
  const std::vector<double> rho = voronoiDensity(voronoiCells(p, cutoff(1.0)));
  EXPECT_NEAR(rho[0], 2.0 / kPi, 1e-12);
  EXPECT_NEAR(rho[1], 2.0 / kPi, 1e-12);
}

TEST(VoronoiDensity, MeasurementAreaInAUniformLatticeHasTheLatticeDensity) {
  const float a = 0.5f;
  const auto p = lattice(20, 20, a, a, 0.0f);
  std::vector<Vec2f> v(p.size(), Vec2f(0.6f, 0.8f));
  const VoronoiCells cells = voronoiCells(p, cutoff(a));
  // Aligned with the cell edges, and cutting cells at arbitrary fractions.
  for (const Polygon& m : {rectangle(Vec2(1.875, 2.0), Vec2(3.875, 4.0)), rectangle(Vec2(2.3, 2.05), Vec2(4.1, 3.7))}) {
    const AreaMeasurement r = measureArea(cells, v, m);
    EXPECT_NEAR(r.area, std::abs(signedArea(m)), 1e-12);
    EXPECT_NEAR(r.density, 4.0, 1e-9);
    EXPECT_NEAR(r.speed, 1.0, 1e-6);
  }
}

TEST(VoronoiDensity, PolygonDiscAreaMatchesElementaryShapes) {
  const Polygon square = rectangle(Vec2(-1, -1), Vec2(1, 1));
  Polygon clockwise = square;
  std::reverse(clockwise.vertices.begin(), clockwise.vertices.end());
  EXPECT_NEAR(polygonDiscArea(square, Vec2::Zero(), 1.0), kPi, 1e-12);
  EXPECT_NEAR(polygonDiscArea(clockwise, Vec2::Zero(), 1.0), kPi, 1e-12);
  EXPECT_NEAR(polygonDiscArea(square, Vec2::Zero(), std::sqrt(2.0)), 4.0, 1e-12);
  EXPECT_NEAR(polygonDiscArea(square, Vec2(1, 0), 0.5), kPi / 8.0, 1e-12);
  EXPECT_NEAR(polygonDiscArea(square, Vec2(5, 0), 1.0), 0.0, 1e-12);
}

TEST(VoronoiDensity, RejectsBadInput) {
  const std::vector<Vec2f> p = {Vec2f(0.0f, 0.0f), Vec2f(20.0f, 0.0f)};
  EXPECT_THROW(voronoiCells(p, cutoff(0.0)), std::invalid_argument);
  EXPECT_THROW(voronoiCells(p, cutoff(1.0, Vec2(-1, -1), Vec2(10, 10))),
               std::invalid_argument);
  const std::vector<Vec2f> nan = {Vec2f(std::nanf(""), 0.0f)};
  EXPECT_THROW(voronoiCells(nan), std::invalid_argument);
  const VoronoiCells cells = voronoiCells(p);
  EXPECT_THROW(measureArea(cells, {}, rectangle(Vec2(0, 0), Vec2(0, 1))), std::invalid_argument);
  const std::vector<Vec2f> oneVelocity = {Vec2f(1.0f, 0.0f)};
  EXPECT_THROW(measureArea(cells, oneVelocity, rectangle(Vec2(0, 0), Vec2(1, 1))), std::invalid_argument);
}

}  // namespace
}  // namespace msim::crowd
