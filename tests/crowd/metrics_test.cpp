// Grid density, speed statistics and the nearest-neighbour validation numbers of Narain (2011,
// sec. 4.5.1) on constructed frames whose answers are known by hand.
#include <gtest/gtest.h>

#include <cmath>
#include <limits>
#include <stdexcept>
#include <vector>

#include "msim/crowd/metrics.hpp"
#include "msim/crowd/metrics_json.hpp"

#include <nlohmann/json.hpp>

namespace msim::crowd {
namespace {

TEST(CrowdMetrics, GridDensityCountsAgentsPerFreeArea) {
  const GridSpec<2> spec(Vec2(0, 0), 0.5, IVec2(4, 2));
  const std::vector<Vec2f> p = {Vec2f(0.1f, 0.1f), Vec2f(0.2f, 0.4f), Vec2f(0.4f, 0.2f), Vec2f(0.3f, 0.3f),
                                Vec2f(1.7f, 0.9f), Vec2f(5.0f, 0.1f), Vec2f(-0.1f, 0.1f)};
  const Grid<double, 2> rho = gridDensity(spec, p);
  EXPECT_DOUBLE_EQ(rho(IVec2(0, 0)), 16.0);  // 4 agents in 0.25 m^2
  EXPECT_DOUBLE_EQ(rho(IVec2(3, 1)), 4.0);
  EXPECT_DOUBLE_EQ(rho(IVec2(1, 0)), 0.0);
  double total = 0.0;
  for (std::size_t k = 0; k < rho.count(); ++k) total += rho[k] * 0.25;
  EXPECT_DOUBLE_EQ(total, 5.0);  // the two agents outside the grid are not counted

  Grid<double, 2> free(spec, 1.0);
  free(IVec2(0, 0)) = 0.5;
  free(IVec2(3, 1)) = 0.0;
  const Grid<double, 2> rhoFree = gridDensity(spec, p, &free);
  EXPECT_DOUBLE_EQ(rhoFree(IVec2(0, 0)), 32.0);
  EXPECT_DOUBLE_EQ(rhoFree(IVec2(3, 1)), 0.0);
}

TEST(CrowdMetrics, SpeedStatisticsOfKnownSpeeds) {
  // Speeds 1..5 m/s in assorted directions (3-4-5 triangles).
  const std::vector<Vec2f> v = {Vec2f(0.0f, 3.0f), Vec2f(-1.0f, 0.0f), Vec2f(3.0f, 4.0f), Vec2f(0.0f, -2.0f),
                                Vec2f(-2.4f, 3.2f)};
  const SpeedStats s = speedStats(v);
  EXPECT_EQ(s.count, 5u);
  EXPECT_NEAR(s.mean, 3.0, 1e-6);
  EXPECT_NEAR(s.stddev, std::sqrt(2.0), 1e-6);
  EXPECT_NEAR(s.min, 1.0, 1e-6);
  EXPECT_NEAR(s.max, 5.0, 1e-6);
  EXPECT_NEAR(s.median, 3.0, 1e-6);
  EXPECT_NEAR(s.p25, 2.0, 1e-6);
  EXPECT_NEAR(s.p95, 4.8, 1e-6);  // type 7: 1 + 0.95 * 4 = 4.8 between the 4th and 5th values
  EXPECT_NEAR(s.p05, 1.2, 1e-6);
  EXPECT_EQ(speedStats({}).count, 0u);
  const nlohmann::json j = toJson(s);
  EXPECT_NEAR(j["median"].get<double>(), 3.0, 1e-6);
}

TEST(CrowdMetrics, NearestNeighbourDistanceOnASquareLatticeIsTheSpacing) {
  const float a = 0.75f;
  std::vector<Vec2f> p;
  for (int j = 0; j < 12; ++j)
    for (int i = 0; i < 12; ++i) p.emplace_back(i * a, j * a);
  const std::vector<float> radii(p.size(), 0.25f);
  const NearestNeighbours nn = nearestNeighbours(p, radii, 1.0);
  for (std::size_t i = 0; i < p.size(); ++i) {
    EXPECT_DOUBLE_EQ(nn.distance[i], 0.75) << i;
    EXPECT_DOUBLE_EQ(nn.ratio[i], 1.5) << i;  // d_min = 0.5
  }
}

TEST(CrowdMetrics, NearestNeighbourRatioUsesTheSumOfRadii) {
  // Agent 0 is 1.0 from agent 1 (radii sum 0.4) and 1.2 from agent 2 (radii sum 1.2): in units of
  // the pair's d_min agent 2 is nearer.
  const std::vector<Vec2f> p = {Vec2f(0.0f, 0.0f), Vec2f(1.0f, 0.0f), Vec2f(0.0f, 1.2f)};
  const std::vector<float> radii = {0.2f, 0.2f, 1.0f};
  const NearestNeighbours nn = nearestNeighbours(p, radii, 2.0);
  EXPECT_NEAR(nn.ratio[0], 1.0, 1e-6);
  EXPECT_NEAR(nn.distance[0], 1.2, 1e-6);
}

// Ten agents of radius 0.25 (d_min = 0.5), far apart except: agents 0, 1 at 0.4 (closer than
// d_min), agents 2, 3 exactly 0.5 apart (touching, not closer).
std::vector<Vec2f> constructedFrame() {
  std::vector<Vec2f> p;
  for (int k = 0; k < 10; ++k) p.emplace_back(10.0f * k, 0.0f);
  p[1] = p[0] + Vec2f(0.4f, 0.0f);
  p[3] = p[2] + Vec2f(0.0f, 0.5f);
  return p;
}

TEST(CrowdMetrics, FractionCloserThanDminAndMeanDenseRatioOnAConstructedFrame) {
  const auto p = constructedFrame();
  const std::vector<float> radii(p.size(), 0.25f);
  const NearestNeighbours nn = nearestNeighbours(p, radii, 2.0);
  EXPECT_EQ(nn.ratio[5], std::numeric_limits<double>::infinity());
  // rho_max = 1: agents 0-3 are dense (>= 0.9), agent 4 too but it has no neighbour.
  std::vector<double> density(p.size(), 0.1);
  density[0] = density[1] = 1.0;
  density[2] = density[3] = 0.95;
  density[4] = 2.0;
  const NearestNeighbourFrame f = nearestNeighbourFrame(nn, density, {.rhoMax = 1.0, .denseFraction = 0.9});
  EXPECT_EQ(f.agents, 10u);
  EXPECT_EQ(f.closer, 2u);
  EXPECT_DOUBLE_EQ(f.fractionCloser(), 0.2);
  EXPECT_EQ(f.dense, 4u);
  EXPECT_EQ(f.denseCloser, 2u);
  EXPECT_NEAR(f.meanDenseRatio(), (0.8 + 0.8 + 1.0 + 1.0) / 4.0, 1e-6);
  EXPECT_NEAR(f.minRatio, 0.8, 1e-6);

  NearestNeighbourAccumulator acc;
  acc.add(f);
  std::vector<double> sparse(p.size(), 0.0);
  acc.add(nearestNeighbourFrame(nn, sparse, {.rhoMax = 1.0}));
  EXPECT_EQ(acc.frames(), 2u);
  EXPECT_EQ(acc.total().agents, 20u);
  EXPECT_DOUBLE_EQ(acc.total().fractionCloser(), 0.2);
  EXPECT_NEAR(acc.total().meanDenseRatio(), 0.9, 1e-6);
  const nlohmann::json j = toJson(acc);
  EXPECT_EQ(j["frames"].get<int>(), 2);
  EXPECT_NEAR(j["meanDenseRatio"].get<double>(), 0.9, 1e-6);
}

TEST(CrowdMetrics, RejectsBadInput) {
  const std::vector<Vec2f> p = {Vec2f(0.0f, 0.0f), Vec2f(1.0f, 0.0f)};
  const std::vector<float> radii = {0.25f, 0.0f};
  EXPECT_THROW(nearestNeighbours(p, radii, 1.0), std::invalid_argument);
  const std::vector<float> good = {0.25f, 0.25f};
  EXPECT_THROW(nearestNeighbours(p, good, 0.0), std::invalid_argument);
  const NearestNeighbours nn = nearestNeighbours(p, good, 2.0);
  const std::vector<double> density = {1.0};
  EXPECT_THROW(nearestNeighbourFrame(nn, density, {.rhoMax = 1.0}), std::invalid_argument);
  const std::vector<Vec2f> nan = {Vec2f(std::nanf(""), 0.0f)};
  EXPECT_THROW(speedStats(nan), std::invalid_argument);
}

}  // namespace
}  // namespace msim::crowd
