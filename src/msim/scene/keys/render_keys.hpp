#pragma once
// The render.* keys every scene has: camera, lights, medium, sky and exposure of the physically
// based renderer (render/frame_renderer.hpp, Stam ch. 5), and the names of the saved grids it
// reads. `msim run` renders each frame with them when render.enabled is true; `msim render`
// renders saved frames with the keys stored in their run.json.
#include <filesystem>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/core/triangle_mesh.hpp"
#include "msim/render/frame_renderer.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

Schema renderSchema();

// Geometry drawn with every frame (render.meshes[], render.points), loaded once.
struct RenderGeometry {
  std::vector<TriangleMesh> meshes;
  std::vector<Vecf<3>> points;
  double pointRadius = 0.0;
  Vec3 pointAlbedo = Vec3::Constant(0.6);
};

struct RenderKeys {
  bool enabled = false;
  bool lastFrameOnly = false;  // render.frames = "last": only the run's last frame is rendered
  bool exr = false;  // also write the linear radiance as OpenEXR next to each PNG
  int slabCells = 8;  // a 2D frame is rendered as a slab this many cells thick
  render::FrameRenderConfig config;
  std::string densityGrid, temperatureGrid, emitterGrid, obstacleGrid, liquidGrid;  // "" = not used
  std::shared_ptr<const RenderGeometry> geometry;  // never null; may be empty
  // The run's grid: the empty medium of a frame that holds only a surface mesh (cloth, solid).
  std::optional<GridSpec<3>> domain;
};

// From the resolved "render" object; InputError naming `source` and the key for values the
// renderer refuses (a camera at its target, a zero light direction, ...) or a mesh or point file
// that does not load. Relative file names are taken from `baseDirectory`.
RenderKeys renderKeys(const nlohmann::json& resolvedRender, const std::string& source,
                      const std::filesystem::path& baseDirectory = {});

}  // namespace msim::scene
