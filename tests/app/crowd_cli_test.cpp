// The "crowd" phenomenon end to end: the seed's validation (Narain 2011, ch. 4.5.1: nearest-neighbour
// spacing in the circle scene; Fig. 4.3: UIC and pairwise resolution are both needed at a doorway),
// the outputs a run writes, --resume, and bad input that names its key.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <limits>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"
#include "msim/io/csv.hpp"
#include "msim/io/vdb.hpp"

namespace {

using nlohmann::json;

json runScene(const std::string& name, const std::string& sceneFile, const std::string& extra) {
  const fs::path dir = scratch(name);
  const Result r = runMsim("run " + sceneFile + " -q --out " + (dir / "out").string() + " " + extra);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return r.exitCode == 0 ? readJson(dir / "out" / "run.json") : json::object();
}

// Fig. 4.3: a 20 m room whose right wall has a 1.2 m door; 400 agents head for an exit behind it.
std::string doorway(const std::string& extra = "") {
  return R"({
  "name": "door", "phenomenon": "crowd",
  "domain": {"min": [0, 0], "max": [20, 20], "resolution": 40},
  "time": {"duration": 20, "fps": 2},
  "goals": [{"name": "out", "shape": {"type": "box", "min": [17, 7], "max": [20, 13]}, "exit": true}],
  "obstacles": [{"shape": {"type": "box", "min": [15, 0], "max": [15.5, 9.4]}},
                {"shape": {"type": "box", "min": [15, 10.6], "max": [15.5, 20]}}],
  "groups": [{"count": 400, "region": {"type": "box", "min": [1, 1], "max": [14, 19]}, "goal": "out"}],
  "outputs": {"mp4": false, "vdb": false, "png": false}, "crowd": {"trajectories": false})" +
         extra + "}\n";
}

double doorwayOverlapFraction(const std::string& name, const std::string& variant) {
  const fs::path dir = scratch(name);
  writeText(dir / "s.json", doorway());
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string() + " " + variant);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  if (r.exitCode != 0) return -1.0;
  return readJson(dir / "out" / "run.json").at("results").at("nearest_neighbour").at("fraction_closer_than_dmin").get<double>();
}

// trajectories.csv of a run folder holds one row per agent and frame of its run.json.
void expectOneTrajectoryRowPerAgentFrame(const fs::path& out, const json& run) {
  const auto table = msim::io::readCsv(out / "trajectories.csv");
  EXPECT_EQ(table.columns, (std::vector<std::string>{"frame", "id", "x", "y", "vx", "vy", "inconsistency"}));
  double agentFrames = 0;
  for (const json& f : run.at("frames")) agentFrames += f.at("agents").get<double>();
  EXPECT_EQ(static_cast<double>(table.rows.size()), agentFrames);
}

}  // namespace

// Fig. 4.5, 10,000 agents on 40 x 40 cells, the first 30 s (they meet in the middle at ~15 s), in
// the seed's model (as the scene file runs) and in the default one.
class CrowdCircle : public ::testing::TestWithParam<std::string> {};

TEST_P(CrowdCircle, KeepsTheSeedsSpacing) {
  const json run = runScene("crowd_circle_" + GetParam(), std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_circle.json",
                            "--frames 150 --set outputs.png=false --set outputs.vdb=false --set outputs.mp4=false "
                            "--set crowd.trajectories=false --set crowd.uic.speed_density=" + GetParam());
  ASSERT_TRUE(run.contains("results"));
  const json& nn = run.at("results").at("nearest_neighbour");
  const double closer = nn.at("fraction_closer_than_dmin").get<double>();
  const double spacing = nn.at("dense_mean_distance_over_dmin").get<double>();
  std::printf("circle (%s): %.4f%% of agent-frames closer than d_min (seed < 0.12%%), mean nearest distance in dense "
              "regions %.3f d_min (seed 1.25) over %.0f dense agent-frames\n",
              GetParam().c_str(), 100 * closer, spacing, nn.at("dense_agent_frames").get<double>());
  EXPECT_LT(closer, 0.005);
  EXPECT_GT(spacing, 1.1);
  EXPECT_LT(spacing, 1.35);
  // The crowd did get dense, and the continuum kept the grid density at f rho_max (within 5%).
  EXPECT_GT(nn.at("dense_agent_frames").get<double>(), 0.5 * nn.at("agent_frames").get<double>());
  double worst = 0.0;
  for (const json& f : run.at("frames")) worst = std::max(worst, f.at("uic_density_ratio_max").get<double>());
  EXPECT_LE(worst, 1.05);
  EXPECT_GT(worst, 0.95);
}

INSTANTIATE_TEST_SUITE_P(CrowdCli, CrowdCircle, ::testing::Values("constant", "weidmann"));

TEST(CrowdCli, DoorwayNeedsBothUicAndPairwiseResolution) {
  // Fig. 4.3 (a) both, (b) without UIC, (c) without collision resolution, in the seed's model
  // (constant speeds): agents overlap unless both act. The default model keeps (a)'s spacing.
  const std::string seed = "--set crowd.uic.speed_density=constant ";
  const double both = doorwayOverlapFraction("door_both", seed);
  const double noUic = doorwayOverlapFraction("door_no_uic", seed + "--set crowd.uic.enabled=false");
  const double noResolution =
      doorwayOverlapFraction("door_no_resolution", seed + "--set crowd.collision_resolution.enabled=false");
  const double defaultModel = doorwayOverlapFraction("door_default", "");
  std::printf("doorway: agent-frames closer than d_min: both %.3f%%, without UIC %.1f%%, without resolution %.1f%%; "
              "default model %.3f%%\n",
              100 * both, 100 * noUic, 100 * noResolution, 100 * defaultModel);
  EXPECT_LT(both, 0.005);
  EXPECT_GT(noUic, 0.05);
  EXPECT_GT(noResolution, 0.05);
  EXPECT_LT(defaultModel, 0.005);
}

TEST(CrowdCli, RunWritesAgentsTrajectoriesPlotsAndFlows) {
  const fs::path dir = scratch("crowd_outputs");
  writeText(dir / "s.json", R"({
  "name": "hall", "phenomenon": "crowd",
  "domain": {"min": [0, 0], "max": [30, 20], "resolution": 30},
  "time": {"duration": 4, "fps": 5},
  "goals": [{"name": "east", "shape": {"type": "box", "min": [27, 0], "max": [30, 20]}, "exit": true},
            {"name": "corner", "shape": {"type": "point", "position": [2, 18], "radius": 0.5}}],
  "obstacles": [{"shape": {"type": "polygon", "vertices": [[14, 8], [16, 8], [16, 12], [14, 12]]}}],
  "groups": [{"count": 60, "region": {"type": "box", "min": [2, 2], "max": [10, 18]}, "goal": "east"},
             {"count": 20, "region": {"type": "circle", "center": [22, 10], "radius": 3}, "goal": "corner",
              "model": "orca"}],
  "inflows": [{"region": {"type": "box", "min": [0.5, 0.5], "max": [2, 19.5]}, "rate": 5, "goal": "east"}],
  "measurement_lines": [{"name": "mid", "from": [12, 0], "to": [12, 20]}],
  "outputs": {"mp4": false}
})");
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const fs::path out = dir / "out";
  const json run = readJson(out / "run.json");
  ASSERT_EQ(run.at("frames").size(), 20u);
  // Inflow at 5 agents/s for 4 s: exactly 20 spawned (fractional credit carried between steps).
  EXPECT_EQ(run.at("frames").back().at("spawned_total").get<int>(), 20);
  // Agents as VDB points with their attributes, and the continuum's grids.
  const auto points = msim::io::readPoints(out / "vdb" / "hall_0020.vdb", "agents");
  EXPECT_EQ(static_cast<double>(points.positions.size()), run.at("frames").back().at("agents").get<double>());
  for (const char* a : {"id", "vx", "vy", "radius", "max_speed", "goal", "group", "model"})
    EXPECT_NE(points.find(a), nullptr) << a;
  const auto grids = msim::io::listVdbGrids(out / "vdb" / "hall_0020.vdb");
  for (const char* g : {"density", "pressure", "free_area"})
    EXPECT_NE(std::find(grids.begin(), grids.end(), g), grids.end()) << g;
  expectOneTrajectoryRowPerAgentFrame(out, run);
  EXPECT_TRUE(fs::exists(out / "trajectories" / "frame_00020.csv"));  // per-frame parts, kept for --resume
  for (const char* f : {"png/hall_0020.png", "fundamental_diagram.png", "time_series.png", "stats.csv"})
    EXPECT_TRUE(fs::exists(out / f)) << f;
  // The crowd walked east through the measurement line.
  EXPECT_GT(run.at("results").at("measurement_lines").at("mid").at("net_crossings").get<double>(), 0.0);
  EXPECT_FALSE(run.at("results").at("fundamental_diagram").empty());
}

TEST(CrowdCli, RoomThatEmptiesBeforeTheEndStillWritesItsTrajectories) {
  // Five agents a few metres from an exit are all out after a few seconds; the frames after that
  // hold no agents, and their (empty) trajectory parts must still join into trajectories.csv.
  const fs::path dir = scratch("crowd_empties");
  writeText(dir / "s.json", R"({
  "name": "empties", "phenomenon": "crowd",
  "domain": {"min": [0, 0], "max": [10, 10], "resolution": 10},
  "time": {"duration": 10, "fps": 2},
  "goals": [{"name": "out", "shape": {"type": "box", "min": [8, 0], "max": [10, 10]}, "exit": true}],
  "groups": [{"count": 5, "region": {"type": "box", "min": [5, 4], "max": [7, 6]}, "goal": "out"}],
  "outputs": {"mp4": false, "vdb": false, "png": false}
})");
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const json run = readJson(dir / "out" / "run.json");
  ASSERT_EQ(run.at("frames").back().at("agents").get<int>(), 0);
  EXPECT_GT(run.at("frames").front().at("agents").get<int>(), 0);
  expectOneTrajectoryRowPerAgentFrame(dir / "out", run);
}

TEST(CrowdCli, ResumeContinuesFromTheLastCompleteFrame) {
  const fs::path dir = scratch("crowd_resume");
  writeText(dir / "s.json", replaced(doorway(), R"("outputs": {"mp4": false, "vdb": false, "png": false}, "crowd": {"trajectories": false})",
                                     R"("outputs": {"mp4": false}, "inflows": [{"region": {"type": "box", "min": [1, 1], "max": [3, 19]}, "rate": 3, "goal": "out"}])"));
  const std::string run = "run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string();
  ASSERT_EQ(runMsim(run + " --frames 6").exitCode, 0);
  const Result resumed = runMsim(run + " --resume");
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  const json record = readJson(dir / "out" / "run.json");
  ASSERT_EQ(record.at("frames").size(), 40u);
  // The inflow keeps its pace across the resume: 3 agents/s over 20 s.
  EXPECT_EQ(record.at("frames").back().at("spawned_total").get<int>(), 60);
  const auto table = msim::io::readCsv(dir / "out" / "trajectories.csv");
  double agentFrames = 0;
  for (const json& f : record.at("frames")) agentFrames += f.at("agents").get<double>();
  EXPECT_EQ(static_cast<double>(table.rows.size()), agentFrames);
}

// A set of exits (goals[].more_shapes): a 20 x 10 m room with a 1.2 m door in each end wall and
// one goal made of the two spaces behind them. Everyone leaves, and each door takes the agents
// nearer to it: about half each, those from the west half of the room through the west door.
TEST(CrowdCli, ExitSetSendsEachAgentToTheNearestDoor) {
  const fs::path dir = scratch("crowd_exit_set");
  writeText(dir / "s.json", R"({
  "name": "exits", "phenomenon": "crowd",
  "domain": {"min": [0, 0], "max": [24, 10], "resolution": 48},
  "time": {"duration": 40, "fps": 1},
  "goals": [{"name": "out", "exit": true, "shape": {"type": "box", "min": [0, 3], "max": [1, 7]},
             "more_shapes": [{"type": "box", "min": [23, 3], "max": [24, 7]}]}],
  "obstacles": [{"shape": {"type": "box", "min": [2, 0], "max": [2.3, 4.4]}},
                {"shape": {"type": "box", "min": [2, 5.6], "max": [2.3, 10]}},
                {"shape": {"type": "box", "min": [21.7, 0], "max": [22, 4.4]}},
                {"shape": {"type": "box", "min": [21.7, 5.6], "max": [22, 10]}}],
  "groups": [{"count": 160, "region": {"type": "box", "min": [3, 0.5], "max": [21, 9.5]}, "goal": "out"}],
  "measurement_lines": [{"name": "west", "from": [1.5, 0], "to": [1.5, 10]},
                        {"name": "east", "from": [22.5, 10], "to": [22.5, 0]}],
  "outputs": {"mp4": false, "vdb": false, "png": false}, "crowd": {"trajectories": false}
})");
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const json run = readJson(dir / "out" / "run.json");
  EXPECT_EQ(run.at("frames").back().at("agents").get<int>(), 0) << "the room empties";
  const json& lines = run.at("results").at("measurement_lines");
  // The lines count crossings with a sign by side; their magnitudes are the agents through each door.
  const double west = std::abs(lines.at("west").at("net_crossings").get<double>());
  const double east = std::abs(lines.at("east").at("net_crossings").get<double>());
  EXPECT_NEAR(west + east, 160.0, 4.0);
  EXPECT_GT(west, 0.35 * 160) << "west " << west << " east " << east;
  EXPECT_GT(east, 0.35 * 160) << "west " << west << " east " << east;
}

// A domain grid finer than an agent (0.25 m cells for agents 0.5 m across) used to stall the
// continuum: one agent alone filled a cell beyond rho_max. The continuum now takes cells of at
// least the agents' diameter, so the doorway empties at 0.25 m cells exactly as at 0.5 m, and
// within 10% of it at 1 m.
TEST(CrowdCli, FineDomainGridDoesNotStallTheCrowd) {
  const auto remaining = [](const std::string& name, int resolution) {
    const fs::path dir = scratch(name);
    writeText(dir / "s.json", replaced(doorway(), R"("resolution": 40)", "\"resolution\": " + std::to_string(resolution)));
    const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    std::vector<int> agents;
    const json run = readJson(dir / "out" / "run.json");
    for (const json& f : run.at("frames")) agents.push_back(f.at("agents").get<int>());
    return agents;
  };
  const std::vector<int> half = remaining("crowd_grid_half", 40), quarter = remaining("crowd_grid_quarter", 80),
                         whole = remaining("crowd_grid_whole", 20);
  EXPECT_EQ(quarter, half);
  ASSERT_EQ(whole.size(), half.size());
  // After 20 s the 1 m continuum has let out within 10% of the agents the 0.5 m one has (the 1.2 m
  // door passes about 2.3 people a second once the queue has formed).
  EXPECT_NEAR(400 - whole.back(), 400 - half.back(), 0.1 * (400 - half.back()));
  EXPECT_GT(400 - half.back(), 30);
  // Cells that do not divide the floor (0.45 m across a 20 m width) leave its walls where the
  // scene puts them: the evacuation room runs and empties within 10% of its time at 0.5 m (139.25 s,
  // docs/evacuation.md).
  const json odd = runScene("crowd_grid_odd", std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_evacuation_room.json",
                            "--set domain.resolution=80 --set outputs.png=false --set outputs.vdb=false "
                            "--set outputs.mp4=false --set crowd.trajectories=false");
  ASSERT_TRUE(odd.contains("results"));
  EXPECT_NEAR(odd.at("results").at("evacuation").at("t100_s").get<double>(), 139.25, 13.9);
}

// The default speed_density = weidmann reads the density of the others in the 1.5 m square ahead: a
// lone walker in a thin crowd keeps Weidmann's free speed, and the middle of a block walks near
// Weidmann's speed for its density (the default's door capacities are in bottleneck_cli_test.cpp).
TEST(CrowdCli, WeidmannSpeedsFollowTheFundamentalDiagram) {
  const auto meanSpeed = [](const std::string& name, int count, const std::string& region, double x0, double x1) {
    const fs::path dir = scratch(name);
    writeText(dir / "s.json", R"({"name": "fd", "phenomenon": "crowd",
      "domain": {"min": [0, 0], "max": [120, 10], "resolution": 240}, "time": {"duration": 4, "fps": 1},
      "crowd": {"uic": {"speed_density": "weidmann"}, "agent": {"max_speed": 1.34}},
      "goals": [{"name": "east", "shape": {"type": "box", "min": [118, 0], "max": [120, 10]}, "exit": true}],
      "groups": [{"count": )" + std::to_string(count) + R"(, "region": )" + region + R"(, "goal": "east"}],
      "outputs": {"mp4": false, "vdb": false, "png": false}})");
    const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
    EXPECT_EQ(r.exitCode, 0) << r.output;
    const auto table = msim::io::readCsv(dir / "out" / "trajectories.csv");
    double sum = 0.0;
    int n = 0;
    for (const auto& row : table.rows)
      if (row[0] == 4.0 && row[2] > x0 && row[2] < x1) sum += std::hypot(row[4], row[5]), ++n;
    return n > 0 ? sum / n : 0.0;
  };
  // 200 agents over 100 x 8 m: 0.25 /m^2, Weidmann 1.33 m/s.
  EXPECT_NEAR(meanSpeed("crowd_fd_sparse", 200, R"({"type": "box", "min": [1, 1], "max": [100, 9]})", 0.0, 120.0), 1.33, 0.1);
  // Blocks of 40 x 10 m at 1, 2 and 2.5 /m^2, measured in their middle: Weidmann 1.05, 0.60 and
  // 0.45 m/s; counting only the others ahead walks up to about 0.12 m/s faster.
  const std::string block = R"({"type": "box", "min": [10, 0], "max": [50, 10]})";
  const double at1 = meanSpeed("crowd_fd_1", 400, block, 22.0, 38.0), at2 = meanSpeed("crowd_fd_2", 800, block, 22.0, 38.0),
               at25 = meanSpeed("crowd_fd_dense", 1000, block, 22.0, 38.0);
  std::printf("speed at 1, 2, 2.5 /m^2: %.3f %.3f %.3f m/s (Weidmann 1.05 0.60 0.45)\n", at1, at2, at25);
  EXPECT_NEAR(at1, 1.05, 0.15);
  EXPECT_NEAR(at2, 0.60, 0.15);
  EXPECT_NEAR(at25, 0.45, 0.07);
  EXPECT_GT(at1, at2);
  EXPECT_GT(at2, at25);
}

// RiMEA test 9's idea on scenes/crowd_evacuation_room.json: 1000 people leave a 30 x 20 m room
// through four 1 m doors, each to the nearest; with the two east doors closed the room takes
// 1.7-2.3 times as long (the same people through half the doors).
TEST(CrowdCli, EvacuationRoomTakesAboutTwiceAsLongThroughTwoExits) {
  const std::string scene = std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_evacuation_room.json";
  const std::string quiet = "--set outputs.png=false --set outputs.vdb=false --set outputs.mp4=false "
                            "--set crowd.trajectories=false --set time.duration=320";
  const auto emptiedAt = [](const json& run) {
    for (const json& f : run.at("frames"))
      if (f.at("agents").get<int>() == 0) return f.at("time_s").get<double>();
    return std::numeric_limits<double>::infinity();
  };
  const json four = runScene("crowd_evacuation_four", scene, quiet);
  const json two = runScene("crowd_evacuation_two", scene,
                            quiet + R"( --set 'goals[0].more_shapes=[{"type": "box", "min": [-3, 13.5], "max": [-1, 16.5]}]')");
  ASSERT_TRUE(four.contains("frames") && two.contains("frames"));
  const double tFour = emptiedAt(four), tTwo = emptiedAt(two);
  std::printf("evacuation room: four exits %.1f s, two %.1f s (ratio %.2f)\n", tFour, tTwo, tTwo / tFour);
  EXPECT_GT(tTwo / tFour, 1.7);
  EXPECT_LT(tTwo / tFour, 2.3);
  // The four doors share the room: each end wall lets out about half.
  const json& lines = four.at("results").at("measurement_lines");
  EXPECT_NEAR(std::abs(lines.at("west").at("net_crossings").get<double>()), 500.0, 60.0);
}

// RiMEA test 7 (a population's walking speeds): 200 agents spread thinly along a 100 m corridor,
// speeds uniform in [0.8, 1.6] m/s, walk east; after 5 s their measured speeds cover that range
// with its mean. Placed at random, a few have someone in the square ahead of them and walk a little
// below their own speed (the default model's fundamental diagram: 0.85 of it at 0.9 /m^2).
TEST(CrowdCli, GroupWalksWithItsSpeedDistribution) {
  const fs::path dir = scratch("crowd_speed_spread");
  writeText(dir / "s.json", R"({
  "name": "spread", "phenomenon": "crowd",
  "domain": {"min": [0, 0], "max": [120, 10], "resolution": 120},
  "time": {"duration": 5, "fps": 1},
  "goals": [{"name": "east", "shape": {"type": "box", "min": [118, 0], "max": [120, 10]}, "exit": true}],
  "groups": [{"count": 200, "region": {"type": "box", "min": [1, 1], "max": [100, 9]}, "goal": "east",
              "speed_distribution": "uniform", "speed_min": 0.8, "speed_max": 1.6}],
  "outputs": {"mp4": false, "vdb": false, "png": false}
})");
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto table = msim::io::readCsv(dir / "out" / "trajectories.csv");
  double sum = 0.0, lo = 1e9, hi = 0.0;
  int n = 0;
  for (const auto& row : table.rows) {
    if (row[0] != 5.0) continue;  // the last frame
    const double speed = std::hypot(row[4], row[5]);
    sum += speed, lo = std::min(lo, speed), hi = std::max(hi, speed), ++n;
  }
  ASSERT_EQ(n, 200);
  std::printf("speeds uniform in [0.8, 1.6]: walked %.2f-%.2f m/s, mean %.3f\n", lo, hi, sum / n);
  EXPECT_NEAR(sum / n, 1.2, 0.05);
  EXPECT_LT(lo, 0.9);
  EXPECT_GT(lo, 0.6);
  EXPECT_GT(hi, 1.5);
  EXPECT_LT(hi, 1.7);
}

TEST(CrowdCli, BadInputNamesTheKey) {
  expectInputError("crowd_3d",
                   replaced(doorway(), R"("min": [0, 0], "max": [20, 20], "resolution")",
                            R"("min": [0, 0, 0], "max": [20, 20, 20], "resolution")"),
                   {"crowds are planar"});
  expectInputError("crowd_region_outside", replaced(doorway(), "[1, 1], \"max\": [14, 19]", "[1, 1], \"max\": [24, 19]"),
                   {"groups[0].region", "outside the domain"});
  expectInputError("crowd_inside_obstacle",
                   replaced(doorway(), R"("count": 400, "region": {"type": "box", "min": [1, 1], "max": [14, 19]})",
                            R"("count": 3, "region": {"type": "box", "min": [15.1, 1], "max": [15.4, 9]})"),
                   {"groups[0].region", "inside obstacles"});
  expectInputError("crowd_self_intersecting",
                   replaced(doorway(), R"({"type": "box", "min": [15, 0], "max": [15.5, 9.4]})",
                            R"({"type": "polygon", "vertices": [[15, 0], [15.5, 9], [15.5, 0], [15, 4]]})"),
                   {"obstacles[0]", "edges 0 and 2 intersect"});
  expectInputError("crowd_rho_max", doorway(R"(, "crowd": {"uic": {"rho_max": 6.0}})"),
                   {"crowd.uic.rho_max", "close packing"});
  expectInputError("crowd_unknown_goal", replaced(doorway(), R"("goal": "out")", R"("goal": "exit")"),
                   {"groups[0].goal", "'exit'"});
  // A goal walled in on all four sides cannot be reached from the room.
  expectInputError("crowd_unreachable",
                   replaced(doorway(), R"("obstacles": [)",
                            R"("obstacles": [{"shape": {"type": "box", "min": [16.5, 6.5], "max": [20, 7]}},
                                {"shape": {"type": "box", "min": [16.5, 13], "max": [20, 13.5]}},
                                {"shape": {"type": "box", "min": [16.5, 7], "max": [17, 13]}},)"),
                   {"cannot be reached"});
  expectInputError("crowd_too_many", replaced(doorway(), R"("count": 400)", R"("count": 4000)"),
                   {"groups[0].count", "do not fit"});
  expectInputError("crowd_zero_speed",
                   replaced(doorway(), R"("goal": "out"}])",
                            R"("goal": "out", "speed_distribution": "uniform", "speed_min": 0, "speed_max": 1.5}])"),
                   {"groups[0].speed_min", "> 0"});
  // A member of an exit set that agents cannot stand in (inside a wall).
  expectInputError("crowd_exit_set_member",
                   replaced(doorway(), R"("exit": true})",
                            R"("exit": true, "more_shapes": [{"type": "box", "min": [15.1, 1], "max": [15.4, 2]}]})"),
                   {"goals[0].more_shapes[0]"});
  expectInputError("crowd_exit_set_point",
                   replaced(doorway(), R"("shape": {"type": "box", "min": [17, 7], "max": [20, 13]}, "exit": true})",
                            R"("shape": {"type": "point", "position": [18, 10]}, "exit": true,
                               "more_shapes": [{"type": "box", "min": [17, 1], "max": [20, 3]}]})"),
                   {"goals[0].more_shapes", "not a point"});
  // An inflow without a rate re-admits the leavers or nothing: 0 only with 'recycle'.
  expectInputError("crowd_inflow_no_rate",
                   replaced(doorway(), R"("obstacles": [)",
                            R"("inflows": [{"region": {"type": "box", "min": [1, 1], "max": [3, 19]}, "rate": 0, "goal": "out"}],
                               "obstacles": [)"),
                   {"inflows[0].rate", "recycle"});
}
