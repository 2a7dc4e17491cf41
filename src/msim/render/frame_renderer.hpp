#pragma once
// One picture of a density field by the physically based path of Stam ch. 5: the transmittance of
// every light through the medium (eq. 5.6), the first-scatter source (eq. 5.7), multiple
// scattering by the diffusion approximation (ch. 5.5, multiple_scattering.hpp) and the ray march
// of the transport equation's integral form (eq. 5.8, volume_renderer.hpp). The scene keys under
// render.* map onto FrameRenderConfig (scene/keys/render_keys.hpp); `msim render` and the runner use it.
#include <optional>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/light.hpp"
#include "msim/render/multiple_scattering.hpp"
#include "msim/render/volume_renderer.hpp"

namespace msim::render {

struct FrameRenderConfig {
  std::optional<Camera> camera;  // none: frameBox of the grid at `width` x `height`
  int width = 640, height = 480;
  std::vector<Light> lights;     // none: defaultLights()
  Medium medium;
  VolumeRenderSettings settings;
  bool multipleScattering = true;
  DiffusionSettings diffusion;
};

struct FrameTimings {
  double lights = 0.0, multipleScattering = 0.0, march = 0.0;  // seconds
  int diffusionCycles = 0;
};

// A key light from the upper right, slightly from the front, so a scene without lights still
// reads as a 3D shape (intensity 10: E p / (4 pi) is about 1 for a unit phase function).
std::vector<Light> defaultLights();

struct FrameResult {
  RenderResult render;
  FrameTimings timings;
};

// Surfaces of a frame (VolumeInput's fields of the same names): solid obstacles as a cell-centred
// signed distance (negative inside) of the density's layout, meshes, point sets, and a liquid's
// level set of that layout (negative inside), drawn as a dielectric with config.settings.liquid.
struct FrameSurfaces {
  const Grid<float, 3>* distance = nullptr;
  std::vector<const TriangleMesh*> meshes = {};
  std::vector<PointSet> points = {};
  const Grid<float, 3>* liquid = nullptr;
};

// `temperature` and `emitter` may be null (no fire). std::invalid_argument for bad settings, grids
// of different layouts, or a camera inside a solid (checked before any light is computed).
FrameResult renderFrame(const FrameRenderConfig& config, const Grid<float, 3>& density,
                        const Grid<float, 3>* temperature = nullptr, const Grid<float, 3>* emitter = nullptr,
                        const FrameSurfaces& surfaces = {});

}  // namespace msim::render
