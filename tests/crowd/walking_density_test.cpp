// The density a pedestrian walks into and its speed on Weidmann's fundamental diagram
// (walking_density.hpp): free areas of the counting square against exact polygon clipping,
// counts on lattices of known spacing, a lone walker's free speed, and the polygon distances that
// size the continuum's cells for a scene's narrowest door.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <random>
#include <stdexcept>
#include <vector>

#include "msim/crowd/free_area.hpp"
#include "msim/crowd/fundamental_diagram.hpp"
#include "msim/crowd/polygon.hpp"
#include "msim/crowd/walking_density.hpp"

using namespace msim;
using namespace msim::crowd;

namespace {

struct Measured {
  std::vector<float> density, speed;
};

Measured measure(WalkingDensity& wd, const std::vector<Vec2f>& people, const std::vector<Vec2f>& heading,
                 float maxSpeed = 1.34f) {
  Measured m{std::vector<float>(people.size()), std::vector<float>(people.size())};
  const std::vector<float> speeds(people.size(), maxSpeed);
  wd.measure(people, heading, speeds, m.density, m.speed);
  return m;
}

}  // namespace

TEST(WalkingDensity, FreeAreaOfTheSquareMatchesExactClipping) {
  // Without obstacles: the full 1.5 m square, and a quarter of it at the box's corner.
  const WalkingDensity open(Vec2(0, 0), Vec2(20, 10), {}, {});
  EXPECT_NEAR(open.freeArea(Vec2(5, 5)), 2.25, 1e-9);
  EXPECT_NEAR(open.freeArea(Vec2(0, 0)), 0.5625, 1e-9);
  EXPECT_NEAR(open.freeArea(Vec2(20, 5)), 1.125, 1e-9);
  // Obstacles whose edges lie on the table's 0.25 m lines: exact.
  const std::vector<Polygon> aligned = {rectangle(Vec2(5, 0), Vec2(5.5, 10))};
  const WalkingDensity wall(Vec2(0, 0), Vec2(20, 10), aligned, {});
  EXPECT_NEAR(wall.freeArea(Vec2(5.25, 5)), 2.25 - 0.5 * 1.5, 1e-9);
  EXPECT_NEAR(wall.freeArea(Vec2(4.4, 5)), 2.25 - 0.15 * 1.5, 1e-9);
  // Any obstacles: the bilinear table misplaces coverage only in the cells that both an obstacle's
  // edge and the square's edge cut, a few of 0.0625 m^2.
  std::mt19937 rng(7);
  std::uniform_real_distribution<double> u(0.0, 1.0);
  std::vector<Polygon> obstacles;
  for (int k = 0; k < 12; ++k) {
    const Vec2 c(1 + 18 * u(rng), 1 + 8 * u(rng));
    obstacles.push_back(u(rng) < 0.5 ? rectangle(c, c + Vec2(0.3 + 2 * u(rng), 0.3 + 2 * u(rng)))
                                     : regularPolygon(c, 0.2 + u(rng), 7));
  }
  const WalkingDensity cluttered(Vec2(0, 0), Vec2(20, 10), obstacles, {});
  double worst = 0.0;
  for (int t = 0; t < 500; ++t) {
    const Vec2 c(1 + 18 * u(rng), 1 + 8 * u(rng));
    const Vec2 lo = c - Vec2(0.75, 0.75);
    // Exact: the square minus each obstacle's part (the obstacles may overlap: sampled instead).
    int inside = 0;
    const int n = 150;
    for (int j = 0; j < n; ++j)
      for (int i = 0; i < n; ++i) {
        const Vec2 x = lo + Vec2((i + 0.5) / n, (j + 0.5) / n) * 1.5;
        bool free = true;
        for (const Polygon& p : obstacles) free = free && !contains(p, x);
        inside += free;
      }
    const double sampled = 2.25 * inside / (n * n);
    worst = std::max(worst, std::abs(cluttered.freeArea(c) - sampled));
  }
  EXPECT_LT(worst, 0.13);
}

TEST(WalkingDensity, CountsTheOthersInTheSquareAhead) {
  // A lattice of spacing 0.5 m (4 /m^2) at x, y = 0.25 + 0.5 k, walking +x. The square ahead of a
  // walker at a lattice point spans [x - 0.25, x + 1.25] x [y - 0.75, y + 0.75]: 3 x 3 people, 8 of
  // them others, 8 / 2.25 = 3.56 /m^2.
  WalkingDensity wd(Vec2(0, 0), Vec2(20, 20), {}, {});
  std::vector<Vec2f> people, heading;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) {
      people.emplace_back(0.25f + 0.5f * i, 0.25f + 0.5f * j);
      heading.emplace_back(1.3f, 0.0f);
    }
  const Measured m = measure(wd, people, heading, 1.4f);
  for (const int i : {10, 20, 30})
    for (const int j : {10, 20, 30}) {
      const std::size_t k = static_cast<std::size_t>(j) * 40 + i;
      EXPECT_NEAR(m.density[k], 8.0 / 2.25, 1e-4) << i << " " << j;
      EXPECT_NEAR(m.speed[k], 1.4 * weidmannSpeed(8.0 / 2.25) / 1.34, 1e-4);
    }
  // Standing still, the square is centred on the person: 8 others again.
  const std::vector<Vec2f> still(heading.size(), Vec2f(0.0f, 0.0f));
  EXPECT_NEAR(measure(wd, people, still).density[20 * 40 + 20], 8.0 / 2.25, 1e-4);
  // Every other column (spacing 1 m along x): 2 x 3 people in the square, 5 others.
  std::vector<Vec2f> sparse, sparseHeading;
  for (std::size_t k = 0; k < people.size(); k += 2) {
    sparse.push_back(people[k]);
    sparseHeading.push_back(heading[k]);
  }
  const Measured half = measure(wd, sparse, sparseHeading);
  EXPECT_NEAR(half.density[20 * 20 + 10], 5.0 / 2.25, 1e-4);
}

TEST(WalkingDensity, LoneWalkerKeepsItsFreeSpeedAndWallsCountAsCovered) {
  const std::vector<Polygon> wall = {rectangle(Vec2(10, 0), Vec2(10.5, 10))};
  WalkingDensity wd(Vec2(0, 0), Vec2(20, 10), wall, {});
  const Measured alone = measure(wd, {Vec2f(3, 5)}, {Vec2f(1, 0)}, 1.2f);
  EXPECT_EQ(alone.density[0], 0.0f);
  EXPECT_EQ(alone.speed[0], 1.2f);
  // Nine people on a 0.5 m lattice just before the wall: walking into it, the square ahead of the
  // middle one ([9.2, 10.7] in x) holds 5 others on 1.0 x 1.5 m^2 of floor (the wall covers the
  // rest); walking away, 5 others on 2.25 m^2.
  std::vector<Vec2f> block, east, west;
  for (int j = -1; j <= 1; ++j)
    for (int i = -1; i <= 1; ++i) {
      block.emplace_back(9.45f + 0.5f * i, 5.0f + 0.5f * j);
      east.emplace_back(1.0f, 0.0f);
      west.emplace_back(-1.0f, 0.0f);
    }
  const Measured intoWall = measure(wd, block, east), away = measure(wd, block, west);
  EXPECT_NEAR(wd.freeArea(Vec2(9.95, 5.0)), 2.25 - 0.5 * 1.5, 1e-9);
  EXPECT_NEAR(intoWall.density[4], 5.0 / 1.5, 1e-4);
  EXPECT_NEAR(away.density[4], 5.0 / 2.25, 1e-4);
  EXPECT_LT(intoWall.speed[4], away.speed[4]);
}

TEST(WalkingDensity, RejectsSettingsOutOfRange) {
  SpeedDensitySettings s;
  s.lookahead = 0.6;  // the snapped square might no longer hold its walker
  EXPECT_THROW(WalkingDensity(Vec2(0, 0), Vec2(10, 10), {}, s), std::invalid_argument);
  s = {};
  s.window = 0.0;
  EXPECT_THROW(WalkingDensity(Vec2(0, 0), Vec2(10, 10), {}, s), std::invalid_argument);
  s = {};
  s.weidmann.gamma = -1.0;
  EXPECT_THROW(WalkingDensity(Vec2(0, 0), Vec2(10, 10), {}, s), std::invalid_argument);
  EXPECT_THROW(WalkingDensity(Vec2(0, 0), Vec2(0, 10), {}, {}), std::invalid_argument);
  WalkingDensity wd(Vec2(0, 0), Vec2(10, 10), {}, {});
  std::vector<float> one(1), two(2);
  const std::vector<Vec2f> p = {Vec2f(1, 1)};
  EXPECT_THROW(wd.measure(p, p, one, two, one), std::invalid_argument);
}

TEST(NarrowestPassage, FindsTheDoorBetweenWallsAndIgnoresGapsNoOneFits) {
  // Two wall pieces leave a 1 m door; a pillar stands 1.2 m beyond one of them and 1.5 m from the
  // box's side; the walls touch the box (no gap).
  const std::vector<Polygon> walls = {rectangle(Vec2(10, 0), Vec2(10.3, 4.5)), rectangle(Vec2(10, 5.5), Vec2(10.3, 10)),
                                      regularPolygon(Vec2(12.0, 2.0), 0.5, 16)};
  EXPECT_NEAR(polygonDistance(walls[0], walls[1]), 1.0, 1e-12);
  EXPECT_NEAR(narrowestPassage(walls, Vec2(0, 0), Vec2(20, 10), 0.5), 1.0, 1e-12);
  std::vector<Polygon> pillarClose = walls;
  pillarClose[2] = regularPolygon(Vec2(10.8, 2.0), 0.5, 16);  // touching the wall: no passage
  EXPECT_NEAR(narrowestPassage(pillarClose, Vec2(0, 0), Vec2(20, 10), 0.5), 1.0, 1e-12);
  // Overlapping and nested polygons are 0 apart; an empty scene has no passage.
  EXPECT_EQ(polygonDistance(rectangle(Vec2(0, 0), Vec2(2, 2)), rectangle(Vec2(1, 1), Vec2(3, 3))), 0.0);
  EXPECT_EQ(polygonDistance(rectangle(Vec2(0, 0), Vec2(4, 4)), rectangle(Vec2(1, 1), Vec2(2, 2))), 0.0);
  EXPECT_EQ(narrowestPassage({}, Vec2(0, 0), Vec2(20, 10), 0.5), std::numeric_limits<double>::infinity());
  // A wall 0.8 m from the box's side leaves that passage.
  EXPECT_NEAR(narrowestPassage({rectangle(Vec2(0.8, 2), Vec2(3, 3))}, Vec2(0, 0), Vec2(20, 10), 0.5), 0.8, 1e-12);
}
