#include "msim/scene/keys/render_keys.hpp"

#include <functional>
#include <stdexcept>
#include <utility>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "msim/scene/keys/json_vectors.hpp"

namespace msim::scene {

namespace {

using nlohmann::json;

Schema cameraSchema() {
  Schema camera = Schema::object("the pinhole camera");
  camera.boolean("auto", true, "frame the whole domain, looking along -z; position, target and up are then ignored");
  camera.vector("position", "m", {0.0, 0.0, 5.0}, "eye point").lengths({3});
  camera.vector("target", "m", {0.0, 0.0, 0.0}, "point at the image centre").lengths({3});
  camera.vector("up", "", {0.0, 1.0, 0.0}, "image up direction").lengths({3});
  camera.number("fov", "deg", 40.0, "vertical field of view").min(0.0, Bound::Exclusive).max(180.0, Bound::Exclusive);
  camera.integer("width", 640, "image width [pixels]").min(1).max(16384);
  camera.integer("height", 480, "image height [pixels]").min(1).max(16384);
  return camera;
}

Schema lightSchema() {
  Schema light = Schema::object("a light source (Stam's reduced incident light, eq. 5.5)");
  light.string("type", "directional", "directional: parallel beam (sun); point; spot: a point light in a cone")
      .choices({"directional", "point", "spot"});
  light.vector("direction", "", {-1.0, -0.7, -0.3}, "direction the light travels (directional, spot)").lengths({3});
  light.vector("position", "m", {0.0, 0.0, 0.0}, "where it is (point, spot)").lengths({3});
  light.vector("colour", "", {1.0, 1.0, 1.0}, "linear RGB").lengths({3}).min(0.0);
  light.number("intensity", "W/m^2 or W/sr", 10.0, "irradiance (directional) or radiant intensity (point, spot)").min(0.0);
  light.number("spot_angle", "deg", 30.0, "cone half-angle (spot)").min(0.0, Bound::Exclusive).max(90.0);
  light.number("spot_softness", "", 0.2, "fraction of the cone fading to zero at its edge (spot)").min(0.0).max(1.0);
  return light;
}

Schema mediumSchema() {
  Schema medium = Schema::object("optical properties of the density field (Stam ch. 5.1)");
  medium.number("extinction", "m^2/kg", 10.0, "sigma_t: extinction per unit density").min(0.0);
  medium.number("albedo", "", 0.9, "Omega: scattered fraction of the extinguished light").min(0.0).max(1.0);
  medium.number("phase_g", "", 0.0, "Henyey-Greenstein asymmetry g (Stam's mu_bar / 3); > 0 scatters forward")
      .min(-1.0, Bound::Exclusive)
      .max(1.0, Bound::Exclusive);
  medium.number("emission", "", 1.0, "fire brightness: radiance per m per unit emitter at the reference temperature")
      .min(0.0);
  medium.number("emission_reference", "K", 1500.0, "temperature whose black body has unit brightness")
      .min(0.0, Bound::Exclusive);
  return medium;
}

Schema meshSchema() {
  Schema mesh = Schema::object("a triangle mesh drawn with every frame (e.g. cloth or a rigid body exported by another tool)");
  mesh.string("file", "an .obj or .ply file, relative to the scene file (run folders) or the current folder").required();
  mesh.number("scale", "", 1.0, "uniform scale of the vertices").min(0.0, Bound::Exclusive);
  mesh.vector("translate", "m", {0.0, 0.0, 0.0}, "translation after scaling").lengths({3});
  return mesh;
}

Schema pointsSchema() {
  Schema points = Schema::object("points drawn as small spheres with every frame (sand grains, particles)");
  points.string("file", "", "a .ply point file; '' for none");
  points.number("radius", "m", 0.005, "sphere radius").min(0.0, Bound::Exclusive);
  points.vector("albedo", "", {0.76, 0.62, 0.42}, "diffuse colour, linear RGB").lengths({3}).min(0.0).max(1.0);
  return points;
}

Schema liquidSchema() {
  Schema liquid = Schema::object("a liquid's surface (render.grids.liquid) drawn as a clear dielectric: Fresnel reflection "
                                 "and refraction, Beer-Lambert absorption inside (docs/render.md)");
  liquid.number("ior", "", 1.33, "refractive index relative to air (water 1.33)").min(1.0, Bound::Exclusive).max(4.0);
  liquid.vector("absorption", "1/m", {0.26, 0.057, 0.011},
                "absorption coefficient per linear RGB channel (pure water, Pope & Fry 1997); larger tints a small "
                "tank as a deeper body of water")
      .lengths({3})
      .min(0.0);
  liquid.integer("max_bounces", 8, "reflections and refractions followed per camera ray").min(1).max(32);
  return liquid;
}

Schema skySchema() {
  Schema sky = Schema::object("a clear sky seen by rays that leave the scene (instead of background), with the "
                              "directional lights as sun disks: reflections and highlights on liquids");
  sky.boolean("enabled", false, "draw the sky; otherwise rays leaving the scene see background");
  sky.vector("zenith", "", {0.25, 0.4, 0.75}, "radiance straight up, linear RGB").lengths({3}).min(0.0);
  sky.vector("horizon", "", {0.7, 0.78, 0.9}, "radiance at and below the horizon, linear RGB").lengths({3}).min(0.0);
  sky.number("sun_radius", "deg", 2.0, "angular radius of each directional light's disk (the sun: 0.27)")
      .min(0.0, Bound::Exclusive)
      .max(30.0);
  return sky;
}

Schema floorSchema() {
  Schema floor = Schema::object("a horizontal floor under the domain (y up), seen from above");
  floor.boolean("enabled", false, "draw the floor");
  floor.number("height", "m", 0.0, "its y");
  floor.vector("albedo", "", {0.6, 0.6, 0.6}, "diffuse colour, linear RGB").lengths({3}).min(0.0).max(1.0);
  floor.number("tile", "m", 0.0, "side of square tiles alternating albedo and tile_albedo; 0 for one colour").min(0.0);
  floor.vector("tile_albedo", "", {0.3, 0.3, 0.3}, "the other tiles' colour").lengths({3}).min(0.0).max(1.0);
  return floor;
}

std::filesystem::path resolvedPath(const std::filesystem::path& base, const std::string& file) {
  const std::filesystem::path p(file);
  return p.is_absolute() || base.empty() ? p : base / p;
}

// Loads render.meshes[] and render.points; errors name the key.
std::shared_ptr<const RenderGeometry> loadGeometry(const json& r, const std::string& source,
                                                   const std::filesystem::path& base) {
  auto g = std::make_shared<RenderGeometry>();
  const json& meshes = r.at("meshes");
  for (std::size_t i = 0; i < meshes.size(); ++i) {
    const std::filesystem::path file = resolvedPath(base, meshes[i].at("file").get<std::string>());
    const std::string key = fmt::format("render.meshes[{}].file", i);
    TriangleMesh mesh;
    try {
      const std::string ext = file.extension().string();
      if (ext == ".obj") mesh = io::readObj(file);
      else if (ext == ".ply") mesh = io::readPlyMesh(file).mesh;
      else throw InputError(fmt::format("{}: '{}' is '{}': expected an .obj or .ply file", source, key, file.string()));
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: '{}': {}", source, key, e.what()));
    }
    const double scale = meshes[i].at("scale").get<double>();
    const Vec3 shift = paddedVec3(meshes[i].at("translate"));
    for (Vec3& v : mesh.vertices) v = v * scale + shift;
    g->meshes.push_back(std::move(mesh));
  }
  const json& points = r.at("points");
  const std::string pointFile = points.at("file");
  if (!pointFile.empty()) {
    try {
      g->points = io::readPlyPoints(resolvedPath(base, pointFile)).positions;
    } catch (const InputError& e) {
      throw InputError(fmt::format("{}: 'render.points.file': {}", source, e.what()));
    }
    g->pointRadius = points.at("radius").get<double>();
    g->pointAlbedo = paddedVec3(points.at("albedo"));
  }
  return g;
}

}  // namespace

Schema renderSchema() {
  Schema r = Schema::object("the physically based picture of each frame (3D scenes; Stam ch. 5)");
  r.boolean("enabled", false, "render the frames into render/<name>_NNNN.png (needs outputs.vdb)");
  r.string("frames", "all", "with enabled: render every frame (and render/<name>_render.mp4) or only the last")
      .choices({"all", "last"});
  r.boolean("exr", false, "also write each picture's linear radiance as a float OpenEXR file (.exr)");
  r.field("camera", cameraSchema());
  r.array("lights", lightSchema(), "light sources; none: one key light from above and in front");
  r.field("medium", mediumSchema());
  r.vector("background", "", {0.02, 0.02, 0.03}, "radiance behind the medium, linear RGB").lengths({3}).min(0.0);
  r.vector("ambient", "", {0.1, 0.1, 0.12}, "sky radiance scattered by the medium, linear RGB").lengths({3}).min(0.0);
  r.vector("surface_albedo", "", {0.6, 0.6, 0.6}, "diffuse colour of obstacles, linear RGB").lengths({3}).min(0.0).max(1.0);
  r.vector("mesh_albedo", "", {0.6, 0.6, 0.6}, "diffuse colour of meshes (render.meshes, a cloth or solid run's surface), linear RGB")
      .lengths({3})
      .min(0.0)
      .max(1.0);
  r.number("exposure", "", 1.0, "radiance multiplier before tone mapping").min(0.0, Bound::Exclusive);
  r.boolean("multiple_scattering", true, "add multiple scattering by the diffusion approximation (ch. 5.5)");
  r.number("step", "cells", 0.5, "ray-march step").min(0.05).max(4.0);
  r.integer("slab_cells", 8, "2D scenes render as a slab this many cells thick, seen face-on").min(1).max(256);
  r.array("meshes", meshSchema(), "triangle meshes drawn with every frame, shaded with mesh_albedo");
  r.field("points", pointsSchema());
  r.field("liquid", liquidSchema());
  r.field("sky", skySchema());
  r.field("floor", floorSchema());
  Schema grids = Schema::object("names of the grids in the saved frames");
  grids.string("density", "density", "scattering and absorbing density");
  grids.string("temperature", "temperature", "temperature [K] for fire emission; '' for none");
  grids.string("emitter", "flame", "emission weight (flame density); '' for none");
  grids.string("obstacle_distance", "obstacle_distance", "signed distance of opaque obstacles [m]; '' for none");
  grids.string("liquid", "liquid_phi", "level set of a liquid [m], negative inside, drawn as its surface; '' for none");
  r.field("grids", grids);
  return r;
}

RenderKeys renderKeys(const json& r, const std::string& source, const std::filesystem::path& baseDirectory) {
  RenderKeys k;
  k.enabled = r.at("enabled").get<bool>();
  k.lastFrameOnly = r.at("frames").get<std::string>() == "last";
  k.exr = r.at("exr").get<bool>();
  render::FrameRenderConfig& c = k.config;
  const json& cam = r.at("camera");
  c.width = cam.at("width").get<int>();
  c.height = cam.at("height").get<int>();
  if (!cam.at("auto").get<bool>()) {
    render::Camera camera;
    camera.position = paddedVec3(cam.at("position"));
    camera.target = paddedVec3(cam.at("target"));
    camera.up = paddedVec3(cam.at("up"));
    camera.fovDegrees = cam.at("fov").get<double>();
    camera.width = c.width;
    camera.height = c.height;
    c.camera = camera;
  }
  const json& lights = r.at("lights");
  for (std::size_t i = 0; i < lights.size(); ++i) {
    const json& l = lights[i];
    render::Light light;
    const std::string type = l.at("type");
    light.type = type == "point"  ? render::Light::Type::Point
                 : type == "spot" ? render::Light::Type::Spot
                                  : render::Light::Type::Directional;
    light.direction = paddedVec3(l.at("direction"));
    light.position = paddedVec3(l.at("position"));
    light.colour = paddedVec3(l.at("colour"));
    light.intensity = l.at("intensity").get<double>();
    light.spotAngleDegrees = l.at("spot_angle").get<double>();
    light.spotSoftness = l.at("spot_softness").get<double>();
    try {
      light.validate();
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: 'render.lights[{}]': {}", source, i, e.what()));
    }
    c.lights.push_back(light);
  }
  const json& m = r.at("medium");
  c.medium.extinction = m.at("extinction").get<double>();
  c.medium.albedo = m.at("albedo").get<double>();
  c.medium.phaseG = m.at("phase_g").get<double>();
  c.medium.emissionScale = m.at("emission").get<double>();
  c.medium.emissionReference = m.at("emission_reference").get<double>();
  c.settings.background = paddedVec3(r.at("background"));
  c.settings.ambient = paddedVec3(r.at("ambient"));
  c.settings.surfaceAlbedo = paddedVec3(r.at("surface_albedo"));
  c.settings.meshAlbedo = paddedVec3(r.at("mesh_albedo"));
  c.settings.exposure = r.at("exposure").get<double>();
  c.settings.stepCells = r.at("step").get<double>();
  k.slabCells = r.at("slab_cells").get<int>();
  c.multipleScattering = r.at("multiple_scattering").get<bool>();
  const json& liquid = r.at("liquid");
  c.settings.liquid.ior = liquid.at("ior").get<double>();
  c.settings.liquid.absorption = paddedVec3(liquid.at("absorption"));
  c.settings.liquid.maxBounces = liquid.at("max_bounces").get<int>();
  const json& sky = r.at("sky");
  c.settings.sky.enabled = sky.at("enabled").get<bool>();
  c.settings.sky.zenith = paddedVec3(sky.at("zenith"));
  c.settings.sky.horizon = paddedVec3(sky.at("horizon"));
  c.settings.sky.sunRadiusDegrees = sky.at("sun_radius").get<double>();
  const json& floor = r.at("floor");
  c.settings.floor.enabled = floor.at("enabled").get<bool>();
  c.settings.floor.height = floor.at("height").get<double>();
  c.settings.floor.albedo = paddedVec3(floor.at("albedo"));
  c.settings.floor.tile = floor.at("tile").get<double>();
  c.settings.floor.tileAlbedo = paddedVec3(floor.at("tile_albedo"));
  // The schema's ranges cover every value; this keeps the keys and the renderer's checks in step.
  const std::pair<const char*, std::function<void()>> checks[] = {{"render.liquid", [&] { c.settings.liquid.validate(); }},
                                                                  {"render.sky", [&] { c.settings.sky.validate(); }},
                                                                  {"render.floor", [&] { c.settings.floor.validate(); }}};
  for (const auto& [key, check] : checks) {
    try {
      check();
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: '{}': {}", source, key, e.what()));
    }
  }
  if (c.camera) {
    try {
      c.camera->validate();
    } catch (const std::invalid_argument& e) {
      throw InputError(fmt::format("{}: 'render.camera': {}", source, e.what()));
    }
  }
  const json& g = r.at("grids");
  k.densityGrid = g.at("density");
  k.temperatureGrid = g.at("temperature");
  k.emitterGrid = g.at("emitter");
  k.obstacleGrid = g.at("obstacle_distance");
  k.liquidGrid = g.at("liquid");
  if (k.densityGrid.empty()) throw InputError(source + ": 'render.grids.density' must name a grid");
  k.geometry = loadGeometry(r, source, baseDirectory);
  return k;
}

}  // namespace msim::scene
