// Every scene shipped in scenes/ (and its subfolders) loads, validates, builds its phenomenon, and `msim info` can
// list each of its parameters with a unit where the parameter has one.
#include <gtest/gtest.h>

#include <filesystem>
#include <string>
#include <vector>

#include "msim/core/error.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/describe.hpp"

namespace fs = std::filesystem;
using namespace msim;

TEST(ShippedScenes, AllLoadBuildAndDescribeWithUnits) {
  int scenes = 0;
  for (const auto& entry : fs::recursive_directory_iterator(fs::path(MSIM_SOURCE_DIR) / "scenes")) {
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

namespace {

// The InputError message of loading steam.json with `overrides`, or "" when it loads.
std::string loadError(const std::vector<std::string>& overrides) {
  try {
    scene::loadScene(fs::path(MSIM_SOURCE_DIR) / "scenes" / "steam.json", overrides);
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

}  // namespace

TEST(SceneFile, AbsurdDurationsRatesAndDomainsAreErrorsNamingTheKey) {
  // Durations and rates beyond any use are refused by key; a frame count that would overflow int
  // (1e308 s at 1e308 fps gives "inf" frames) cannot pass as a small one.
  EXPECT_NE(loadError({"time.duration=1e308"}).find("'time.duration'"), std::string::npos);
  EXPECT_NE(loadError({"time.fps=1e308"}).find("'time.fps'"), std::string::npos);
  const std::string frames = loadError({"time.duration=1e5", "time.fps=1e3"});
  EXPECT_NE(frames.find("'time.duration'"), std::string::npos) << frames;
  EXPECT_NE(frames.find("'time.fps'"), std::string::npos) << frames;
  EXPECT_NE(frames.find("frames"), std::string::npos) << frames;
  EXPECT_EQ(loadError({"time.duration=3600", "time.fps=24"}), "");
  // 1e400 is beyond double: not a number (in a scene file, json_file_test checks the message).
  EXPECT_NE(loadError({"time.duration=1e400"}).find("'time.duration'"), std::string::npos);
  // Integers beyond exact double or long long are not integers msim can use.
  EXPECT_NE(loadError({"domain.resolution=1e300"}).find("'domain.resolution'"), std::string::npos);
  EXPECT_NE(loadError({"domain.resolution=18446744073709551615"}).find("'domain.resolution'"), std::string::npos);
  // A domain whose extent overflows double.
  const std::string extent = loadError({"domain.min=[-1e308, 0, 0]", "domain.max=[1e308, 1, 1]"});
  EXPECT_NE(extent.find("'domain.max' - 'domain.min'"), std::string::npos) << extent;
  // Cells per axis beyond int, and a cell count beyond 64 bits, are refused by the memory check.
  EXPECT_NE(loadError({"domain.resolution=1073741824"}).find("'domain.resolution'"), std::string::npos);
}
