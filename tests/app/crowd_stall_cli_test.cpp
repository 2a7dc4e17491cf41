// A crowd never stops silently: no shipped crowd scene stalls (agents with free space ahead that
// want to walk, standing still), and a continuum on cells finer than the agents, which does stall,
// is reported by a warning and counted in run.json.
#include <gtest/gtest.h>

#include <algorithm>
#include <fstream>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace {

using nlohmann::json;

// The first `seconds` of a scene without pictures: the run's output (exit code checked) and run.json.
json runFirstSeconds(const fs::path& scene, const std::string& name, double seconds, const std::string& extra,
                     std::string* output = nullptr) {
  const fs::path out = scratch("stall_" + name) / "out";
  const Result r = runMsim("run " + scene.string() + " --out " + out.string() + " --set time.duration=" +
                           std::to_string(seconds) +
                           " --set outputs.png=false --set outputs.mp4=false --set outputs.vdb=false "
                           "--set crowd.trajectories=false " + extra);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  if (output) *output = r.output;
  return r.exitCode == 0 ? readJson(out / "run.json") : json::object();
}

}  // namespace

TEST(CrowdStallCli, NoShippedCrowdSceneStalls) {
  int checked = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(MSIM_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    std::ifstream in(entry.path());
    if (json::parse(in, nullptr, true, true).value("phenomenon", "") != "crowd") continue;
    ++checked;
    SCOPED_TRACE(entry.path().string());
    const json run = runFirstSeconds(entry.path(), entry.path().stem().string(), 10.0, "");
    ASSERT_TRUE(run.contains("results"));
    EXPECT_EQ(run.at("results").at("stalled_frames").get<int>(), 0);
    double slowest = 1e9;
    for (const json& f : run.at("frames"))
      if (f.at("time_s").get<double>() > 0.0 &&
          f.at("free_walkers").get<double>() >= std::max(5.0, 0.01 * f.at("agents").get<double>()))
        slowest = std::min(slowest, f.at("free_walkers_mean_speed_mps").get<double>());
    if (slowest < 1e9) {  // scenes of one or a few walkers have no frame with enough of them
      std::printf("%s: free walkers at %.2f m/s or faster\n", entry.path().filename().string().c_str(), slowest);
      EXPECT_GT(slowest, 0.2);
    }
  }
  EXPECT_GE(checked, 15);
}

TEST(CrowdStallCli, ContinuumOnCellsFinerThanTheAgentsIsReported) {
  // 0.25 m continuum cells for agents 0.5 m across: one agent fills a cell beyond rho_max and the
  // evacuation room's crowd stands still within seconds.
  std::string output;
  const json run = runFirstSeconds(fs::path(MSIM_SOURCE_DIR) / "scenes" / "crowd_evacuation_room.json", "fine_cells",
                                   6.0, "--set crowd.uic.cell_size=0.25", &output);
  ASSERT_TRUE(run.contains("results"));
  EXPECT_GT(run.at("results").at("stalled_frames").get<int>(), 10);
  EXPECT_NE(output.find("the crowd stalls at t ="), std::string::npos) << output;
}
