// Crowd lookahead end to end (Golas ch. 3.8, the seed notes' check L15) on
// scenes/crowd_lookahead_swap.json: looking ahead everywhere makes agents yield to crowds they
// would have passed, and curtailing it where the crowd moves inconsistently wins the time back.
#include <gtest/gtest.h>

#include <fstream>
#include <iterator>
#include <string>

#include <nlohmann/json.hpp>

#include "cli_harness.hpp"

namespace {

using nlohmann::json;

const std::string kScene = std::string(MSIM_SOURCE_DIR) + "/scenes/crowd_lookahead_swap.json";

json run(const std::string& name, const std::string& sets) {
  const fs::path dir = scratch(name);
  const Result r = runMsim("run " + kScene + " -q --out " + (dir / "out").string() +
                           " --set outputs.png=false --set outputs.mp4=false --set outputs.vdb=false" + sets);
  EXPECT_EQ(r.exitCode, 0) << r.output;
  EXPECT_TRUE(fs::exists(dir / "out" / "inconsistency.png"));
  return r.exitCode == 0 ? readJson(dir / "out" / "run.json") : json::object();
}

double completion(const json& run) { return run.at("results").at("evacuation").at("t100_s").get<double>(); }

double meanInconsistency(const json& run) {
  double sum = 0.0;
  for (const json& f : run.at("frames")) sum += f.at("inconsistency").get<double>();
  return sum / static_cast<double>(run.at("frames").size());
}

}  // namespace

TEST(CrowdLookahead, CurtailingBeatsConstantLookaheadOnTheSwap) {
  // L15: some sigma_max gives a completion time at most 0.9 of constant lookahead's; the scene's
  // sigma_max = 3 m/s^2. Every agent arrives in all three runs, and the scene's metric is
  // measured in each frame.
  const json constant = run("lookahead_constant", " --set crowd.lookahead.sigma_max=0");
  const json curtailed = run("lookahead_curtailed", "");
  const json plain = run("lookahead_plain", " --set crowd.lookahead.levels=0");
  ASSERT_FALSE(constant.empty());
  ASSERT_FALSE(curtailed.empty());
  ASSERT_FALSE(plain.empty());
  for (const json* r : {&constant, &curtailed, &plain}) EXPECT_EQ(r->at("frames").back().at("agents").get<int>(), 0);
  testing::Test::RecordProperty("t100_constant_s", std::to_string(completion(constant)));
  testing::Test::RecordProperty("t100_curtailed_s", std::to_string(completion(curtailed)));
  testing::Test::RecordProperty("t100_plain_s", std::to_string(completion(plain)));
  EXPECT_LE(completion(curtailed), 0.9 * completion(constant));
  EXPECT_GT(meanInconsistency(plain), 0.0);
  EXPECT_DOUBLE_EQ(plain.at("results").at("inconsistency").at("mean").get<double>(), meanInconsistency(plain));
}

TEST(CrowdLookahead, BadSettingsNameTheirKey) {
  // Levels beyond 16, a base step of 0 and a coarsening below 1: exit 2 naming the key, no frames.
  std::string scene;
  {
    std::ifstream in(kScene);
    scene.assign(std::istreambuf_iterator<char>(in), std::istreambuf_iterator<char>());
  }
  const std::string lookahead = R"("lookahead": {"levels": 8, "sigma_max": 3.0})";
  ASSERT_NE(scene.find(lookahead), std::string::npos);
  expectInputError("lookahead_levels", replaced(scene, lookahead, R"("lookahead": {"levels": 17})"), {"crowd.lookahead.levels"});
  expectInputError("lookahead_base_step", replaced(scene, lookahead, R"("lookahead": {"levels": 8, "base_step": 0})"),
                   {"crowd.lookahead.base_step"});
  expectInputError("lookahead_coarsening", replaced(scene, lookahead, R"("lookahead": {"levels": 8, "coarsening": 0.5})"),
                   {"crowd.lookahead.coarsening"});
}
