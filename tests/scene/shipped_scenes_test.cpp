// Every scene shipped in scenes/ loads, validates, builds its phenomenon, and `msim info` can
// list each of its parameters with a unit where the parameter has one.
#include <gtest/gtest.h>

#include <filesystem>

#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/describe.hpp"

namespace fs = std::filesystem;
using namespace msim;

TEST(ShippedScenes, AllLoadBuildAndDescribeWithUnits) {
  int scenes = 0;
  for (const auto& entry : fs::directory_iterator(fs::path(MSIM_SOURCE_DIR) / "scenes")) {
    if (entry.path().extension() != ".json") continue;
    ++scenes;
    SCOPED_TRACE(entry.path().string());
    const scene::Scene s = scene::loadScene(entry.path());
    StageTimers timers;
    EXPECT_NE(s.type->create(s, timers), nullptr);
    const auto rows = scene::describe(scene::sceneSchema(*s.type), s.resolved);
    bool sawDomainUnit = false, sawTimeUnit = false;
    for (const auto& row : rows) {
      if (row.path == "domain.max") sawDomainUnit = row.unit == "m";
      if (row.path == "time.duration") sawTimeUnit = row.unit == "s";
    }
    EXPECT_TRUE(sawDomainUnit);
    EXPECT_TRUE(sawTimeUnit);
    EXPECT_GT(rows.size(), 20u);
    EXPECT_LT(s.memoryEstimate, 4.0 * 1024 * 1024 * 1024) << "shipped scenes must run on a small machine";
  }
  EXPECT_GE(scenes, 1);
}

TEST(SceneFile, OverridesAndDerivedGrid) {
  const fs::path file = fs::path(MSIM_SOURCE_DIR) / "scenes" / "steam.json";
  const scene::Scene s = scene::loadScene(file, {"domain.resolution=32", "time.fps=10"});
  EXPECT_EQ(s.dimensions, 3);
  EXPECT_EQ(s.resolution.maxCoeff(), 32);
  EXPECT_NEAR(s.dx * 32, 0.6, 1e-12);  // the longest axis sets dx
  EXPECT_EQ(s.frameCount, 40);          // 4 s at 10 fps
}
