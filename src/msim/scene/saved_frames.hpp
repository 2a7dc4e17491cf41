#pragma once
// Rendering frames that were saved as VDB files, without simulating again: `msim render` on a run
// folder (its run.json holds the scene's render.* keys) or on one .vdb file, and the runner when a
// scene sets render.enabled. Every picture is made from the file, so a re-render matches the run's.
#include <filesystem>
#include <string>
#include <vector>

#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"
#include "msim/render/frame_renderer.hpp"
#include "msim/scene/keys/render_keys.hpp"

namespace msim::scene {

// Renders one saved frame into `png` (and its .exr twin when keys.exr). InputError naming the
// file for a missing or unreadable file, a missing density grid, or a picture the renderer refuses
// (a camera inside an obstacle); the temperature, emitter and obstacle grids are used when present.
void renderSavedFrame(const io::VdbFile& frame, const RenderKeys& keys, const std::filesystem::path& png,
                      render::FrameTimings* timings = nullptr);

struct RenderJob {
  std::filesystem::path input;   // a run folder (with run.json and vdb/) or one .vdb file
  std::filesystem::path output;  // folder for a run (default <input>/render), file for a .vdb (default <input>.png)
                                 // (with render.exr, an .exr of the same name beside each picture)
  std::vector<std::string> overrides;  // "render.key=value" changes to the stored keys
  bool lastFrameOnly = false;          // a run folder: render only its last frame
  bool showProgress = true;
};

// Renders every frame of the job (or the last); returns the pictures written. InputError for a path that is
// neither, a run folder without run.json or frames, or bad keys.
std::vector<std::filesystem::path> renderSavedFrames(const RenderJob& job);

}  // namespace msim::scene
