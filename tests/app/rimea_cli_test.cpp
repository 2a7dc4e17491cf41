// The RiMEA guideline's verification tests that apply to a planar crowd, run on their scenes in
// scenes/rimea/ with the outcomes the guideline expects (docs/evacuation.md).
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/csv.hpp"

namespace {

using nlohmann::json;

// Runs scenes/rimea/<name>.json without pictures; the run folder.
fs::path runRimea(const std::string& name) {
  const fs::path out = scratch("rimea_" + name) / "out";
  const Result r = runMsim("run " + std::string(MSIM_SOURCE_DIR) + "/scenes/rimea/" + name + ".json -q --out " +
                           out.string() + " --set outputs.png=false --set outputs.mp4=false");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return out;
}

double lastOut(const fs::path& out) { return readJson(out / "run.json").at("results").at("evacuation").at("t100_s").get<double>(); }

}  // namespace

// Test 1: one person at 1.33 m/s covers 40 m of a 2 m corridor in 26-34 s, and the same corridor
// turned by 30 degrees against the grid takes the same time.
TEST(RimeaCli, Test1CorridorAtItsSpeedStraightAndTurned) {
  const double straight = lastOut(runRimea("rimea_01_corridor"));
  const double turned = lastOut(runRimea("rimea_01_corridor_rotated"));
  EXPECT_GE(straight, 26.0);
  EXPECT_LE(straight, 34.0);
  EXPECT_NEAR(turned, straight, 1.0);
}

// Test 6: twenty people go round a left-hand corner without passing through the walls: every
// trajectory point keeps a body radius (0.25 m) from them, to 1 cm, and all leave.
TEST(RimeaCli, Test6CornerWithoutCrossingTheWalls) {
  const fs::path out = runRimea("rimea_06_corner");
  EXPECT_EQ(readJson(out / "run.json").at("frames").back().at("agents").get<int>(), 0);
  const auto table = msim::io::readCsv(out / "trajectories.csv");
  const auto outsideBox = [](double x, double y, double x0, double y0, double x1, double y1) {
    const double dx = std::max({x0 - x, 0.0, x - x1}), dy = std::max({y0 - y, 0.0, y - y1});
    return (x > x0 && x < x1 && y > y0 && y < y1) ? -1.0 : std::hypot(dx, dy);
  };
  double clearance = 1e9;
  for (const auto& row : table.rows) {
    const double x = row[2], y = row[3];
    clearance = std::min({clearance, outsideBox(x, y, 0, 0, 14, 10), outsideBox(x, y, 0, 12, 12, 24), x, 14.0 - x, 24.0 - y});
  }
  EXPECT_GT(table.rows.size(), 200u);
  EXPECT_GT(clearance, 0.24);
}

// Test 7: a population's walking speeds (Weidmann's adults, 1.34 +- 0.26 m/s truncated to
// 0.6-2.0 m/s): the 50 walkers' speeds after 2 s have that mean and spread within their sampling
// error and stay in the range.
TEST(RimeaCli, Test7WalkingSpeedsOfAPopulation) {
  const auto table = msim::io::readCsv(runRimea("rimea_07_speeds") / "trajectories.csv");
  std::vector<double> speeds;
  for (const auto& row : table.rows)
    if (row[0] == 4.0) speeds.push_back(std::hypot(row[4], row[5]));
  ASSERT_EQ(speeds.size(), 50u);
  double mean = 0.0, var = 0.0;
  for (double s : speeds) mean += s / 50.0;
  for (double s : speeds) var += (s - mean) * (s - mean) / 49.0;
  EXPECT_NEAR(mean, 1.34, 0.1);  // 2.7 standard errors
  EXPECT_GT(std::sqrt(var), 0.18);
  EXPECT_LT(std::sqrt(var), 0.34);
  EXPECT_GE(*std::min_element(speeds.begin(), speeds.end()), 0.6 - 1e-3);
  EXPECT_LE(*std::max_element(speeds.begin(), speeds.end()), 2.0 + 1e-3);
}

// Test 12 (the effect of a bottleneck): 150 people pass a 1 m wide passage between two rooms; the
// queue forms in front of it (above 2 /m^2 in the 3 x 6 m before it) and not behind it (below
// 1 /m^2 in the 3 x 6 m after it), and everyone leaves.
TEST(RimeaCli, Test12QueueFormsBeforeTheBottleneckNotBehindIt) {
  const fs::path out = runRimea("rimea_12_bottleneck");
  EXPECT_EQ(readJson(out / "run.json").at("frames").back().at("agents").get<int>(), 0);
  const auto table = msim::io::readCsv(out / "trajectories.csv");
  std::vector<int> before(1000, 0), after(1000, 0);
  for (const auto& row : table.rows) {
    const auto frame = static_cast<std::size_t>(row[0]);
    const double x = row[2], y = row[3];
    if (frame >= before.size() || y < 2.0 || y >= 8.0) continue;
    if (x >= 7.0 && x < 10.0) ++before[frame];
    if (x >= 14.0 && x < 17.0) ++after[frame];
  }
  EXPECT_GT(*std::max_element(before.begin(), before.end()) / 18.0, 2.0);
  EXPECT_LT(*std::max_element(after.begin(), after.end()) / 18.0, 1.0);
}

// Counter-flow: two groups of 60 meet head-on in a 4 m corridor and pass each other: no deadlock
// (the mean speed, which falls to about 0.3 m/s while they pass, never below 0.2 m/s), everyone
// out at the far end.
TEST(RimeaCli, CounterFlowPassesWithoutDeadlock) {
  const json run = readJson(runRimea("rimea_counterflow") / "run.json");
  EXPECT_EQ(run.at("frames").back().at("agents").get<int>(), 0);
  double slowest = 1e9;
  for (const json& f : run.at("frames"))
    if (f.at("agents").get<int>() > 0) slowest = std::min(slowest, f.at("mean_speed_mps").get<double>());
  std::printf("counter-flow: slowest mean speed %.2f m/s, all out after %.1f s\n", slowest,
              run.at("results").at("evacuation").at("t100_s").get<double>());
  EXPECT_GT(slowest, 0.2);
}
