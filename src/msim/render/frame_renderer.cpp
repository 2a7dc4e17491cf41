#include "msim/render/frame_renderer.hpp"

#include <chrono>
#include <stdexcept>

#include "msim/core/seconds_since.hpp"

namespace msim::render {

std::vector<Light> defaultLights() {
  Light key;
  key.type = Light::Type::Directional;
  key.direction = Vec3(-1.0, -0.7, -0.3);
  key.colour = Vec3(1.0, 0.97, 0.92);
  key.intensity = 10.0;
  return {key};
}

FrameResult renderFrame(const FrameRenderConfig& config, const Grid<float, 3>& density,
                        const Grid<float, 3>* temperature, const Grid<float, 3>* emitter,
                        const FrameSurfaces& surfaces) {
  FrameResult result;
  const std::vector<Light> lights = config.lights.empty() ? defaultLights() : config.lights;
  const GridSpec<3>& spec = density.spec();
  const Camera camera = config.camera ? *config.camera
                                      : frameBox(spec.origin, spec.upper(), config.width, config.height);
  if (surfaces.distance && !surfaces.distance->sameLayout(density))
    throw std::invalid_argument("frame renderer: the surface distance grid does not have the density grid's layout");
  checkCameraOutsideSolids(camera.position, surfaces.distance, surfaces.meshes);

  auto start = std::chrono::steady_clock::now();
  std::vector<Grid<float, 3>> transmittances;
  transmittances.reserve(lights.size());
  for (const Light& light : lights)
    transmittances.push_back(
        lightTransmittance(density, light, config.medium, config.settings.stepCells, surfaces.distance));
  result.timings.lights = secondsSince(start);

  std::optional<Grid<float, 3>> fluence;
  if (config.multipleScattering && config.medium.albedo > 0.0) {
    start = std::chrono::steady_clock::now();
    DiffusionMedium medium;
    medium.extinction = config.medium.extinction;
    medium.albedo = config.medium.albedo;
    medium.phaseG = config.medium.phaseG;
    DiffusionStats stats;
    const Grid<float, 3> source = firstScatterSource(density, lights, config.medium, transmittances);
    fluence = solveMultipleScattering<3>(density, source, medium, config.diffusion, &stats);
    result.timings.multipleScattering = secondsSince(start);
    result.timings.diffusionCycles = stats.cycles;
  }
  VolumeInput input;
  input.density = &density;
  input.temperature = temperature;
  input.emitter = temperature ? emitter : nullptr;
  input.fluence = fluence ? &*fluence : nullptr;
  input.transmittances = &transmittances;
  input.surfaceDistance = surfaces.distance;
  input.meshes = surfaces.meshes;
  input.points = surfaces.points;
  input.liquid = surfaces.liquid;
  result.render = renderVolume(input, camera, lights, config.medium, config.settings);
  result.timings.march = result.render.stats.secondsMarch;
  return result;
}

}  // namespace msim::render
