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
  wd.setPeople(people);
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
  // walker at a lattice point spans [x - 0.25, x + 1.25] x [y - 0.75, y + 0.75]: 3 x 3 points, 8 of
  // them others, 8 / 2.25 = 3.56 /m^2.
  WalkingDensity wd(Vec2(0, 0), Vec2(20, 20), {}, {});
  std::vector<Vec2f> people, heading;
  for (int j = 0; j < 40; ++j)
    for (int i = 0; i < 40; ++i) {
      people.emplace_back(0.25f + 0.5f * i, 0.25f + 0.5f * j);
      heading.emplace_back(1.3f, 0.0f);
    }
  const Measured m = measure(wd, people, heading, 1.4f);
  const std::size_t middle = 20 * 40 + 20;
  EXPECT_NEAR(m.density[middle], 8.0 / 2.25, 1e-5);
  EXPECT_NEAR(m.speed[middle], 1.4 * weidmannSpeed(8.0 / 2.25) / 1.34, 1e-5);
  // At the east edge the square ahead leaves the box: 1 x 3 points on 0.5 x 1.5 m^2 of floor.
  const std::size_t east = 20 * 40 + 39;
  EXPECT_NEAR(m.density[east], 2.0 / (0.5 * 1.5), 1e-5);
  // Walking -y instead: the same count by symmetry.
  std::vector<Vec2f> south(heading.size(), Vec2f(0.0f, -1.0f));
  EXPECT_NEAR(measure(wd, people, south).density[middle], 8.0 / 2.25, 1e-5);
}

TEST(WalkingDensity, LoneWalkerKeepsItsFreeSpeedAndWallsCountAsCovered) {
  const std::vector<Polygon> wall = {rectangle(Vec2(10, 0), Vec2(10.5, 10))};
  WalkingDensity wd(Vec2(0, 0), Vec2(20, 10), wall, {});
  const Measured alone = measure(wd, {Vec2f(3, 5)}, {Vec2f(1, 0)}, 1.2f);
  EXPECT_EQ(alone.density[0], 0.0f);
  EXPECT_EQ(alone.speed[0], 1.2f);
  // Two walkers side by side 0.6 m before a 0.5 m wall: the square ahead of each, x in
  // [9.15, 10.65], holds the other on 1.0 x 1.5 m^2 of floor.
  const Measured pair = measure(wd, {Vec2f(9.4f, 5.0f), Vec2f(9.4f, 5.6f)}, {Vec2f(1, 0), Vec2f(1, 0)});
  EXPECT_NEAR(pair.density[0], 1.0 / 1.5, 1e-4);
  EXPECT_NEAR(pair.speed[0], weidmannSpeed(1.0 / 1.5), 1e-5);
  // Standing still (no preferred direction): the square is centred on the walker.
  const Measured still = measure(wd, {Vec2f(9.0f, 5.0f), Vec2f(9.5f, 5.0f)}, {Vec2f(0, 0), Vec2f(0, 0)});
  EXPECT_NEAR(still.density[0], 1.0 / 2.25, 1e-4);
}

TEST(WalkingDensity, RejectsSettingsOutOfRange) {
  SpeedDensitySettings s;
  s.lookahead = 0.75;  // the square would no longer hold its walker
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
