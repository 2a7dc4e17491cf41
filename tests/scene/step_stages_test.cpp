// A fluid run's stage table (the end-of-run summary and run.json's timings) breaks each smoke,
// gas and liquid step into the solver's own stages, each step's time counted once.
#include <gtest/gtest.h>

#include <filesystem>
#include <algorithm>
#include <map>
#include <string>

#include "msim/core/timer.hpp"
#include "msim/scene/phenomenon.hpp"
#include "msim/scene/scene_file.hpp"

namespace fs = std::filesystem;
using namespace msim;

namespace {

// Stage name -> calls after `steps` steps of a shipped scene at 16 cells.
std::map<std::string, std::uint64_t> stagesAfterSteps(const std::string& scene, int steps) {
  const scene::Scene s = scene::loadScene(fs::path(MSIM_SOURCE_DIR) / "scenes" / scene, {"domain.resolution=16"});
  StageTimers timers;
  const auto phenomenon = s.type->create(s, timers);
  for (int k = 0; k < steps; ++k) phenomenon->step(std::min(phenomenon->stableTimestep(), 1.0 / s.fps));
  std::map<std::string, std::uint64_t> calls;
  for (const StageTime& t : timers.table()) calls[t.name] = t.calls;
  return calls;
}

}  // namespace

TEST(StepStages, SmokeStepsShowTheSolversStages) {
  const auto calls = stagesAfterSteps("plume_3d.json", 3);
  for (const char* stage : {"smoke: sources", "smoke: advect velocity", "smoke: forces", "smoke: project",
                            "smoke: advect scalars"}) {
    ASSERT_TRUE(calls.count(stage)) << stage;
    EXPECT_EQ(calls.at(stage), 3u) << stage;
  }
  EXPECT_FALSE(calls.count("smoke: step"));  // no stage holding the others: the total counts each once
}

TEST(StepStages, GasStepsShowTheSolversStages) {
  const auto calls = stagesAfterSteps("steam.json", 3);
  for (const char* stage : {"gas: emit", "gas: transport density", "gas: transport temperature", "gas: decay"}) {
    ASSERT_TRUE(calls.count(stage)) << stage;
    EXPECT_EQ(calls.at(stage), 3u) << stage;
  }
  EXPECT_FALSE(calls.count("gas: emit + transport"));
}

TEST(StepStages, LiquidStepsShowTheSolversStages) {
  const auto calls = stagesAfterSteps("dam_break_3d.json", 3);
  for (const char* stage : {"liquid: surface", "liquid: pressure", "liquid: grid to particles"}) {
    ASSERT_TRUE(calls.count(stage)) << stage;
    EXPECT_GE(calls.at(stage), 3u) << stage;  // one per substep
  }
  EXPECT_FALSE(calls.count("liquid: step"));
}
