// Fuzzing the scene loader with mutations of every shipped scene: each mutated scene loads (it
// may still be a valid scene) or is refused with an InputError, and `msim validate` exits 0 or 2
// with a message on a sample of them.
#include <gtest/gtest.h>

#include <algorithm>
#include <filesystem>
#include <vector>

#include "../app/cli_harness.hpp"
#include "fuzz_case.hpp"
#include "msim/scene/scene_file.hpp"
#include "mutator.hpp"

namespace msim::fuzz {
namespace {

constexpr int kCasesPerScene = 64;

std::vector<std::filesystem::path> shippedScenes() {
  std::vector<std::filesystem::path> scenes;
  for (const auto& e : std::filesystem::recursive_directory_iterator(std::filesystem::path(MSIM_SOURCE_DIR) / "scenes"))
    if (e.path().extension() == ".json") scenes.push_back(e.path());
  std::sort(scenes.begin(), scenes.end());
  return scenes;
}

// A scratch folder beside which the scenes' mesh folders appear as they do beside the originals.
std::filesystem::path sceneScratch(const std::string& name) {
  const auto dir = fuzzScratch(name);
  const auto scenes = std::filesystem::path(MSIM_SOURCE_DIR) / "scenes";
  for (const auto& e : std::filesystem::directory_iterator(scenes))
    if (e.is_directory()) std::filesystem::create_directory_symlink(e.path(), dir / e.path().filename());
  return dir;
}

TEST(SceneLoaderFuzz, MutatedShippedScenesLoadOrFailWithInputError) {
  const auto scenes = shippedScenes();
  ASSERT_GE(scenes.size(), 20u);
  const auto dir = sceneScratch("scenes");
  Mutator mutator(20261202);
  Outcomes outcomes;
  for (const auto& scene : scenes) {
    const std::string original = readBytes(scene);
    for (int k = 0; k < kCasesPerScene; ++k) {
      const std::string name = scene.stem().string() + "_" + std::to_string(k);
      const auto input = dir / (name + ".json");
      writeBytes(input, mutator.mutateText(original));
      runCase(name, input, [&] { scene::loadScene(input); }, outcomes);
    }
  }
  std::printf("%zu scenes x %d mutations: %d loaded, %d refused with InputError\n", scenes.size(), kCasesPerScene,
              outcomes.accepted, outcomes.rejected);
  // The mutations must mostly reach past the JSON parser and the schema into real refusals, but
  // leave some scenes valid: both outcomes occur.
  EXPECT_GT(outcomes.rejected, 0);
  EXPECT_GT(outcomes.accepted, 0);
}

// Through the program: exit 0 with "ok", or exit 2 with "msim: error:", never a crash.
TEST(SceneLoaderFuzz, ValidateExitsWithZeroOrTwoAndAMessage) {
  const auto dir = sceneScratch("validate");
  Mutator mutator(7);
  int refused = 0;
  for (const char* sceneName : {"swirl_2d", "plume_2d", "crowd_doorway"}) {
    const std::string original = readBytes(std::filesystem::path(MSIM_SOURCE_DIR) / "scenes" / (std::string(sceneName) + ".json"));
    for (int k = 0; k < 8; ++k) {
      const auto input = dir / (std::string(sceneName) + "_" + std::to_string(k) + ".json");
      writeBytes(input, mutator.mutateText(original));
      const Result r = runMsim("validate " + input.string());
      if (r.exitCode == 2) {
        ++refused;
        EXPECT_NE(r.output.find("msim: error: "), std::string::npos) << input << "\n" << r.output;
      } else {
        EXPECT_EQ(r.exitCode, 0) << input << "\n" << r.output;
      }
    }
  }
  EXPECT_GT(refused, 0);
}

}  // namespace
}  // namespace msim::fuzz
