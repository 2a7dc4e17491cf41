#include "msim/scene/scene_file.hpp"

#include <cmath>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/scene/keys/json_vectors.hpp"
#include "msim/scene/keys/render_keys.hpp"
#include "msim/core/system_memory.hpp"
#include "msim/scene/schema/json_file.hpp"
#include "msim/scene/schema/key_suggestion.hpp"
#include "msim/scene/schema/override.hpp"
#include "msim/scene/schema/resolve.hpp"

namespace msim::scene {

namespace {

// Cell indices are int; a domain this long along one axis is refused by the memory check anyway
// unless it is a line of cells.
constexpr long long kMaxCellsPerAxis = 1LL << 30;
// A run writes every frame: more than this is a typo in time.duration or time.fps, not a plan.
constexpr double kMaxFrames = 1e7;

Schema domainSchema() {
  Schema domain = Schema::object("the simulated box");
  domain.vector("min", "m", 3, "lower corner; 2 numbers make a 2D scene").lengths({2, 3}).required();
  domain.vector("max", "m", 3, "upper corner; snapped up to whole cells").lengths({2, 3}).required();
  domain.integer("resolution", 64, "cells along the longest axis (dx = longest extent / resolution)")
      .min(1)
      .max(kMaxCellsPerAxis);
  Schema sides = Schema::object("what each side of the box does to the flow");
  for (const char* side : {"x_min", "x_max", "y_min", "y_max", "z_min", "z_max"})
    sides.string(side, "open", "open: gas flows in and out; closed: a wall").choices({"open", "closed"});
  domain.field("boundaries", sides);
  return domain;
}

Schema timeSchema() {
  Schema time = Schema::object("frames and substeps");
  // Upper bounds far beyond any use (three years; a frame every 10 microseconds) keep absurd
  // values from passing as a plausible frame count.
  time.number("duration", "s", 2.0, "simulated time").min(0.0, Bound::Exclusive).max(1e8);
  time.number("fps", "1/s", 24.0, "frames written per second of simulated time").min(0.0, Bound::Exclusive).max(1e5);
  time.number("cfl", "", 0.9, "fraction of the largest stable substep actually taken")
      .min(0.0, Bound::Exclusive)
      .max(1.0);
  time.integer("max_substeps", 2000, "a frame needing more substeps stops the run (CFL blow-up guard)").min(1);
  return time;
}

Schema mpiSchema() {
  Schema mpi = Schema::object("how `mpirun -np N msim run` splits the grid among the N processes (docs/parallel.md)");
  mpi.integer("ghost_layers", 0, "cells each block keeps of its neighbours; 0: what the schemes read").min(0);
  mpi.vector("blocks", "", {0.0, 0.0, 0.0},
             "processes along x, y, z (their product is N); zeros: the lattice with the least interface");
  return mpi;
}

Schema outputsSchema() {
  Schema outputs = Schema::object("what each frame writes");
  outputs.boolean("vdb", true, "OpenVDB volumes per frame (needed by --resume)");
  outputs.boolean("vdb_half_float", false,
                  "store float and vector grids as 16-bit halves: half the size, --resume no longer bit-exact");
  outputs.number("vdb_fog_tolerance", "", 1e-6,
                 "fog-volume values (densities) at or below this are inactive; 0 keeps every nonzero value "
                 "(then --resume is bit-exact)")
      .min(0.0);
  outputs.boolean("png", true, "preview picture per frame");
  outputs.boolean("mp4", true, "movie of the previews at the end (needs ffmpeg)");
  Schema preview = Schema::object("the per-frame preview picture");
  preview.string("view_axis", "z", "the camera looks down this axis (3D)").choices({"x", "y", "z"});
  preview.string("up_axis", "y", "image up; the light shines down it").choices({"x", "y", "z"});
  preview.number("extinction", "m^2/kg", 10.0, "extinction per unit density").min(0.0, Bound::Exclusive);
  preview.number("albedo", "", 0.9, "scattered fraction of extinguished light").min(0.0).max(1.0);
  preview.integer("width", 480, "minimum picture width (integer upscaling)").min(16).max(8192);
  outputs.field("preview", preview);
  return outputs;
}

const PhenomenonType& pickPhenomenon(const nlohmann::json& raw, const std::string& source) {
  std::vector<std::string> names;
  for (const auto& t : phenomenonTypes()) names.push_back(t.name);
  const std::string list = quotedList(names);
  if (!raw.is_object()) throw InputError(source + ": expected a JSON object at the top level");
  if (!raw.contains("phenomenon"))
    throw InputError(fmt::format("{}: missing required key 'phenomenon' (one of {})", source, list));
  const auto& value = raw.at("phenomenon");
  if (!value.is_string())
    throw InputError(fmt::format("{}: key 'phenomenon' expected one of {}, got {}", source, list, value.dump()));
  const std::string name = value.get<std::string>();
  if (const PhenomenonType* t = findPhenomenonType(name)) return *t;
  const auto hint = closestMatch(name, names);
  throw InputError(fmt::format("{}: key 'phenomenon' is '{}', expected one of {}{}", source, name, list,
                               hint ? fmt::format("; did you mean '{}'?", *hint) : std::string()));
}

}  // namespace

Schema sceneSchema(const PhenomenonType& type) {
  Schema root = Schema::object("an msim scene");
  root.string("name", "scene", "used for output file names");
  root.string("description", "", "free text");
  root.string("phenomenon", "what is simulated").required();
  root.field("domain", domainSchema());
  root.field("time", timeSchema());
  root.field("outputs", outputsSchema());
  root.field("mpi", mpiSchema());
  root.field("render", renderSchema());
  type.declare(root);
  return root;
}

Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides) {
  nlohmann::json raw = loadJsonFile(file);
  const std::string source = file.string();
  for (const auto& assignment : overrides) applyOverride(raw, assignment);

  Scene scene;
  scene.file = file;
  scene.type = &pickPhenomenon(raw, source);
  scene.resolved = resolve(sceneSchema(*scene.type), raw, source);

  const auto& domain = scene.resolved.at("domain");
  const auto& lo = domain.at("min");
  const auto& hi = domain.at("max");
  if (lo.size() != hi.size())
    throw InputError(fmt::format("{}: 'domain.min' has {} numbers but 'domain.max' has {}; both must be 2 (2D) or 3 (3D)",
                                 source, lo.size(), hi.size()));
  scene.dimensions = static_cast<int>(lo.size());
  const Vec3 minCorner = paddedVec3(lo), maxCorner = paddedVec3(hi);
  double longest = 0.0;
  for (int a = 0; a < scene.dimensions; ++a) {
    const double extent = maxCorner[a] - minCorner[a];
    if (!std::isfinite(extent))
      throw InputError(fmt::format("{}: 'domain.max' - 'domain.min' along {} is beyond the range of numbers ({} - {})",
                                   source, "xyz"[a], maxCorner[a], minCorner[a]));
    if (!(extent > 0.0))
      throw InputError(fmt::format("{}: 'domain.max' must exceed 'domain.min' on every axis (axis {} has extent {})",
                                   source, "xyz"[a], extent));
    longest = std::max(longest, extent);
  }
  const long long resolution = domain.at("resolution").get<long long>();
  scene.origin = minCorner;
  scene.dx = longest / static_cast<double>(resolution);
  for (int a = 0; a < scene.dimensions; ++a)
    scene.resolution[a] = std::max(1, static_cast<int>(std::lround((maxCorner[a] - minCorner[a]) / scene.dx)));

  const auto& time = scene.resolved.at("time");
  scene.fps = time.at("fps").get<double>();
  const double duration = time.at("duration").get<double>();
  const double frames = std::round(duration * scene.fps);
  if (!(frames <= kMaxFrames))
    throw InputError(fmt::format("{}: 'time.duration' = {} s at 'time.fps' = {} gives {:.3g} frames; at most {:.0f} "
                                 "frames can be written",
                                 source, duration, scene.fps, frames, kMaxFrames));
  scene.frameCount = std::max(1, static_cast<int>(frames));

  // Refuse before anything is allocated: a run that swaps or is killed by the OOM killer helps no one.
  // The cell count in double: the axes' product can exceed 64 bits before this check.
  const double cells = double(scene.resolution.x()) * double(scene.resolution.y()) * double(scene.resolution.z());
  scene.memoryEstimate = cells * scene.type->bytesPerCell(scene.dimensions, scene.resolved);
  const double available = static_cast<double>(availableMemoryBytes());
  if (available > 0.0 && scene.memoryEstimate > available)
    throw InputError(fmt::format(
        "{}: 'domain.resolution' = {} gives {} x {}{} = {:.4g} cells needing about {}, more than the {} available on "
        "this machine; lower 'domain.resolution'",
        source, resolution, scene.resolution.x(), scene.resolution.y(),
        scene.dimensions == 3 ? fmt::format(" x {}", scene.resolution.z()) : std::string(), cells,
        formatBytes(scene.memoryEstimate), formatBytes(available)));
  return scene;
}

}  // namespace msim::scene
