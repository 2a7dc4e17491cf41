// The "smoke" phenomenon end to end: a run writes volumes and pictures, --resume continues
// bit-exactly (fire fields and a moving obstacle included), bad input names its key, NaN or CFL
// blow-ups stop with a message naming the step and the field, and an obstacle that will run into
// a closed side is warned of.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <limits>
#include <vector>

#include "cli_harness.hpp"
#include "msim/io/vdb.hpp"

namespace {

// A small, fast 2D smoke scene: a hot, smoky, fuel-laden source in a box open at the top, a
// swinging paddle, fire on. `extra` is spliced into the top-level object.
std::string tinySmoke(const std::string& extra = "", const std::string& sources = "") {
  return R"({
  "name": "tiny",
  "phenomenon": "smoke",
  "domain": {"min": [0, 0], "max": [1, 1], "resolution": 32,
             "boundaries": {"x_min": "closed", "x_max": "closed", "y_min": "closed", "y_max": "open"}},
  "time": {"duration": 0.5, "fps": 8},
  "smoke": {"buoyancy": {"alpha": 0.05, "beta": 0.01}, "vorticity_confinement": 0.2},
  "fire": {"enabled": true, "reaction_frequency": 5.0},
  "sources": [{"shape": {"type": "sphere", "center": [0.5, 0.15], "radius": 0.1}, "mode": "set",
               "density": 1.0, "temperature": 900.0, "fuel": 0.5})" +
         sources + R"(],
  "obstacles": [{"shape": {"type": "box", "min": [0.2, 0.5], "max": [0.3, 0.7]}, "oscillation": [0.1, 0.0],
                 "frequency": 1.0}],
  "outputs": {"mp4": false}
  )" + extra + "}\n";
}

}  // namespace

TEST(SmokeCli, RunWritesVolumesPicturesAndStatistics) {
  const fs::path dir = scratch("smoke_run");
  writeText(dir / "s.json", tinySmoke());
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string());
  ASSERT_EQ(r.exitCode, 0) << r.output;
  const auto grids = msim::io::listVdbGrids(dir / "out" / "vdb" / "tiny_0004.vdb");
  for (const char* g : {"density", "temperature", "fuel", "flame", "vel_face_x", "vel_face_y", "pressure", "obstacle_distance"})
    EXPECT_NE(std::find(grids.begin(), grids.end(), g), grids.end()) << g;
  EXPECT_TRUE(fs::exists(dir / "out" / "png" / "tiny_0004.png"));
  std::ifstream stats(dir / "out" / "stats.csv");
  std::string header;
  std::getline(stats, header);
  for (const char* column : {"smoke_mass_kg", "max_divergence_1_s", "flame_kg", "max_temperature_K"})
    EXPECT_NE(header.find(column), std::string::npos) << column << " in " << header;
}

TEST(SmokeCli, ResumeContinuesBitExactly) {
  const fs::path dir = scratch("smoke_resume");
  // Densities kept down to the last nonzero value: the saved frame is the whole state.
  writeText(dir / "s.json", replaced(tinySmoke(), "\"mp4\": false", "\"mp4\": false, \"vdb_fog_tolerance\": 0"));
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --out " + (dir / "full").string()).exitCode, 0);
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 2 --out " + (dir / "split").string()).exitCode, 0);
  const Result resumed = runMsim("run " + scene + " -q --resume --out " + (dir / "split").string());
  ASSERT_EQ(resumed.exitCode, 0) << resumed.output;
  for (const char* grid : {"density", "temperature", "flame", "vel_face_y"}) {
    const auto a = msim::io::readFloatGrid(dir / "full" / "vdb" / "tiny_0004.vdb", grid);
    const auto b = msim::io::readFloatGrid(dir / "split" / "vdb" / "tiny_0004.vdb", grid);
    ASSERT_EQ(a.count(), b.count());
    EXPECT_EQ(0, std::memcmp(a.data().data(), b.data().data(), a.count() * sizeof(float))) << grid;
  }
}

TEST(SmokeCli, BadInputNamesTheKey) {
  expectInputError("smoke_source_outside", replaced(tinySmoke(), "[0.5, 0.15]", "[3.0, 0.15]"),
                   {"sources[0].shape", "outside"});
  expectInputError("smoke_obstacle_outside", replaced(tinySmoke(), "\"min\": [0.2, 0.5], \"max\": [0.3, 0.7]",
                                                      "\"min\": [2.2, 0.5], \"max\": [2.3, 0.7]"),
                   {"obstacles[0].shape", "outside the domain"});
  expectInputError("smoke_fuel_without_fire", replaced(tinySmoke(), "\"enabled\": true", "\"enabled\": false"),
                   {"sources[0].fuel", "fire.enabled"});
  expectInputError("smoke_wall_velocity_open",
                   replaced(tinySmoke(), "\"vorticity_confinement\": 0.2",
                            "\"vorticity_confinement\": 0.2, \"wall_velocity\": {\"y_max\": [0, 1]}"),
                   {"smoke.wall_velocity.y_max", "open"});
  expectInputError("smoke_net_inflow",
                   replaced(replaced(tinySmoke(), "\"y_max\": \"open\"", "\"y_max\": \"closed\""),
                            "\"vorticity_confinement\": 0.2",
                            "\"vorticity_confinement\": 0.2, \"wall_velocity\": {\"x_min\": [1, 0]}"),
                   {"smoke.wall_velocity", "closed on every side"});
  expectInputError("smoke_upwind_cfl",
                   replaced(tinySmoke(), "\"vorticity_confinement\": 0.2",
                            "\"vorticity_confinement\": 0.2, \"cfl\": 1.5, "
                            "\"advection\": {\"building_block\": \"upwind\"}"),
                   {"smoke.cfl", "upwind"});
  expectInputError("smoke_source_window", tinySmoke("", R"(, {"shape": {"type": "sphere", "center": [0.5, 0.5],
      "radius": 0.1}, "start": 0.4, "stop": 0.2})"),
                   {"sources[1].stop", "sources[1].start"});
}

TEST(SmokeCli, NanInAFieldStopsNamingFieldAndStep) {
  // A saved frame whose density holds a NaN, resumed: the first step must stop the run.
  const fs::path dir = scratch("smoke_nan");
  writeText(dir / "s.json", tinySmoke());
  const std::string scene = (dir / "s.json").string();
  ASSERT_EQ(runMsim("run " + scene + " -q --frames 1 --out " + (dir / "out").string()).exitCode, 0);
  const fs::path frame = dir / "out" / "vdb" / "tiny_0001.vdb";
  msim::io::VdbWriter writer;
  for (const auto& name : msim::io::listVdbGrids(frame)) {
    if (name == "vel") continue;
    auto grid = msim::io::readFloatGrid(frame, name);
    if (name == "density") grid[grid.count() / 2] = std::numeric_limits<float>::quiet_NaN();
    writer.addFloatGrid(name, grid);
  }
  writer.write(frame);
  const Result r = runMsim("run " + scene + " -q --resume --out " + (dir / "out").string());
  EXPECT_EQ(r.exitCode, 3) << r.output;
  EXPECT_NE(r.output.find("step "), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("non-finite"), std::string::npos) << r.output;
}

TEST(SmokeCli, CflBlowUpStopsWithAMessage) {
  const fs::path dir = scratch("smoke_cfl");
  writeText(dir / "s.json", tinySmoke());
  const Result r = runMsim("run " + (dir / "s.json").string() + " -q --out " + (dir / "out").string() +
                           " --set time.max_substeps=2 --set smoke.buoyancy.beta=50");
  EXPECT_EQ(r.exitCode, 3) << r.output;
  EXPECT_NE(r.output.find("max_substeps"), std::string::npos) << r.output;
  EXPECT_NE(r.output.find("step "), std::string::npos) << r.output;
}

TEST(SmokeCli, ObstacleRunningIntoAClosedSideIsWarnedOf) {
  // The paddle driven at 2 m/s towards the closed side x_max reaches it by t = 0.375 s (frames of
  // 1/8 s); swinging in place it never does.
  const fs::path dir = scratch("smoke_obstacle_wall");
  writeText(dir / "into_wall.json", replaced(tinySmoke(), "\"oscillation\": [0.1, 0.0]", "\"velocity\": [2.0, 0.0]"));
  const Result into = runMsim("run " + (dir / "into_wall.json").string() + " --out " + (dir / "into").string());
  EXPECT_EQ(into.exitCode, 0) << into.output;
  EXPECT_NE(into.output.find("obstacles[0] reaches the closed side x_max of the domain by t = 0.375 s"), std::string::npos)
      << into.output;
  writeText(dir / "swinging.json", tinySmoke());
  const Result swinging = runMsim("run " + (dir / "swinging.json").string() + " --out " + (dir / "swinging").string());
  EXPECT_EQ(swinging.exitCode, 0) << swinging.output;
  EXPECT_EQ(swinging.output.find("reaches the closed side"), std::string::npos) << swinging.output;
}
