// The crowd stress model end to end (Golas ch. 4) on scenes/crowd_stress_merge.json: the merge
// packs past the critical density, every friction solve converges, the crowd pressure is measured
// per frame over space and time, with the strain rate and the run's peak pressure map; bad settings exit 2 naming their key.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace {

using nlohmann::json;

const std::string kMergeScene = std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_stress_merge.json";
const std::string kLoveParade = std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_love_parade.json";

// run.json of `scene` run for `seconds` without pictures into dir/out (an empty object on failure).
json runScene(const std::string& scene, const fs::path& dir, int seconds) {
  const Result r = runMsim("run " + scene + " -q --out " + (dir / "out").string() + " --set time.duration=" +
                           std::to_string(seconds) + " --set outputs.png=false --set outputs.mp4=false --set outputs.vdb=false");
  EXPECT_EQ(r.exitCode, 0) << r.output;
  return r.exitCode == 0 ? readJson(dir / "out" / "run.json") : json::object();
}

}  // namespace

TEST(CrowdStressCli, MergePacksPastTheCriticalDensityAndEverySolveConverges) {
  const fs::path dir = scratch("stress_merge");
  const json run = runScene(kMergeScene, dir, 40);
  ASSERT_FALSE(run.empty());
  const json& stress = run.at("results").at("stress");
  EXPECT_GT(stress.at("friction_solves").get<long>(), 0);
  EXPECT_EQ(stress.at("unconverged_solves").get<long>(), 0);
  double densest = 0.0;
  for (const json& f : run.at("frames")) {
    densest = std::max(densest, f.at("max_density_per_m2").get<double>());
    EXPECT_GE(f.at("pressure_max_per_s2").get<double>(), 0.0);
    EXPECT_LE(f.at("pressure_temporal_mean_per_s2").get<double>(), f.at("pressure_temporal_max_per_s2").get<double>());
    EXPECT_LE(f.at("strain_rate_mean_per_s").get<double>(), f.at("strain_rate_max_per_s").get<double>());
  }
  EXPECT_GT(densest, 3.5);  // the stress model's regime
  EXPECT_GT(run.at("frames").back().at("agents").get<int>(), 500);
  // A packed crowd that moves: people's velocities vary in time and space.
  EXPECT_GT(run.at("frames").back().at("pressure_temporal_mean_per_s2").get<double>(), 0.0);
  EXPECT_GT(run.at("frames").back().at("strain_rate_mean_per_s").get<double>(), 0.0);
  const json& turbulence = run.at("results").at("turbulence");
  EXPECT_GE(turbulence.at("pressure_temporal_peak_per_s2").get<double>(),
            run.at("frames").back().at("pressure_temporal_max_per_s2").get<double>() - 1e-6);
  EXPECT_TRUE(fs::exists(dir / "out" / "pressure_map.png"));
}

// The Love-Parade-like counter-flow: visitors from both tunnel inlets meet the people coming down
// the ramp at its foot, where the crowd packs past the critical density; the run reports its
// samples by density (crowd cells and agents) and its peak pressure where people walk.
TEST(CrowdStressCli, LoveParadeStreamsMeetAtTheRampFoot) {
  const json run = runScene(kLoveParade, scratch("love_parade"), 35);
  ASSERT_FALSE(run.empty());
  const json& results = run.at("results");
  EXPECT_EQ(results.at("stress").at("unconverged_solves").get<long>(), 0);
  // Net crossings upwards: people come down past the ramp's top, none yet past its foot.
  EXPECT_LT(results.at("measurement_lines").at("ramp_top").at("net_crossings").get<double>(), -100.0);
  double densest = 0.0;
  for (const json& f : run.at("frames")) densest = std::max(densest, f.at("max_density_per_m2").get<double>());
  EXPECT_GT(densest, 3.5);
  const json& turbulence = results.at("turbulence");
  long samples = 0, agentSamples = 0;
  for (const json& b : turbulence.at("by_density")) {
    samples += b.at("samples").get<long>();
    agentSamples += b.at("agent_samples").get<long>();
    for (const char* share : {"turbulent_fraction", "backward_fraction"}) {
      EXPECT_GE(b.at(share).get<double>(), 0.0);
      EXPECT_LE(b.at(share).get<double>(), 1.0);
    }
  }
  EXPECT_GT(samples, 0);
  EXPECT_GT(agentSamples, 0);
  const double x = turbulence.at("peak_at_m")[0].get<double>(), y = turbulence.at("peak_at_m")[1].get<double>();
  EXPECT_TRUE(y < 14.0 || (x > 31.0 && x < 49.0)) << x << ", " << y;  // the tunnel or the ramp
}

TEST(CrowdStressCli, BadSettingsNameTheirKey) {
  // Densities in the wrong order, friction outside [0, 1], summaries that would start after the
  // run's end: exit 2 naming the key, no frames.
  std::string scene;
  {
    std::ifstream in(kMergeScene);
    scene.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string turbulence = R"("turbulence": {"enabled": true})";
  ASSERT_NE(scene.find(turbulence), std::string::npos);
  expectInputError("stress_densities",
                   replaced(scene, turbulence, R"("turbulence": {"enabled": true, "critical_density": 6})"),
                   {"crowd.turbulence.yield_density", "critical_density"});
  expectInputError("stress_friction", replaced(scene, turbulence, R"("turbulence": {"enabled": true, "friction": 1.5})"),
                   {"crowd.turbulence.friction"});
  expectInputError("stress_summaries", replaced(scene, turbulence, R"("turbulence": {"enabled": true}, "summaries_from": 90)"),
                   {"crowd.summaries_from", "time.duration"});
}
