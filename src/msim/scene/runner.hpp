#pragma once
// The time loop: fixed frames of 1/fps, each advanced in CFL-adaptive substeps, written
// atomically (VDB, PNG), with run.json and stats.csv kept current after every frame so an
// interrupted run can be resumed from its last complete frame.
#include <filesystem>
#include <string>

#include "msim/scene/scene_file.hpp"

namespace msim::scene {

struct RunOptions {
  std::filesystem::path outDir;
  int frameLimit = -1;  // --frames: stop after this many frames in total (-1: the scene's count)
  bool resume = false;
  bool showProgress = true;
  std::string commandLine;  // recorded in run.json
};

enum class RunStatus { Complete, Interrupted };

// Runs the scene. Throws InputError (bad resume state) or SimulationError (blow-up); in both
// cases run.json records the failure before the exception leaves.
RunStatus runScene(const Scene& scene, const RunOptions& options);

// Output file of frame `frame` (1-based) for a given folder and extension: "<dir>/<name>_0007.<ext>".
std::filesystem::path frameFile(const std::filesystem::path& dir, const std::string& name, int frame,
                                 const std::string& extension);

}  // namespace msim::scene
