#pragma once
// A scene file read, overridden (--set), validated against its schema and turned into the derived
// quantities every phenomenon needs: grid geometry, frame count, memory estimate.
#include <filesystem>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/core/grid_spec.hpp"
#include "msim/scene/phenomenon.hpp"

namespace msim::scene {

struct Scene {
  std::filesystem::path file;
  nlohmann::json resolved;      // every key present, defaults filled in
  const PhenomenonType* type = nullptr;
  int dimensions = 3;
  Vec3 origin = Vec3::Zero();   // lower corner [m] (z = 0 in 2D)
  double dx = 0.0;              // cell size [m]
  IVec3 resolution = IVec3::Ones();  // cells per axis (z = 1 in 2D)
  int frameCount = 0;
  double fps = 24.0;
  double memoryEstimate = 0.0;  // bytes

  std::size_t cellCount() const {
    return static_cast<std::size_t>(resolution.x()) * resolution.y() * resolution.z();
  }
  template <int D>
  GridSpec<D> gridSpec() const {
    GridSpec<D> g;
    g.dx = dx;
    for (int a = 0; a < D; ++a) {
      g.origin[a] = origin[a];
      g.res[a] = resolution[a];
    }
    return g;
  }
  // Directory that relative file names in the scene are resolved against.
  std::filesystem::path directory() const { return file.parent_path(); }
  std::string name() const { return resolved.at("name").get<std::string>(); }
};

// The root schema for a phenomenon: common keys plus the phenomenon's own.
Schema sceneSchema(const PhenomenonType& type);

// Reads, applies `overrides` ("key.path=value"), validates and derives. Throws InputError naming
// the file and key for any problem, including a domain too large for this machine's memory.
Scene loadScene(const std::filesystem::path& file, const std::vector<std::string>& overrides = {});

}  // namespace msim::scene
