#pragma once
// Builds Shapes from resolved scene JSON (see scene/schema/shape_schema.hpp).
#include <filesystem>
#include <memory>
#include <string_view>

#include <nlohmann/json.hpp>

#include "msim/geometry/shape.hpp"

namespace msim::geometry {

// `shape` is a resolved shape object ({"type": "sphere", "center": [...], "radius": ...}, ...).
// Mesh files ({"type": "mesh", "file": "cup.obj", "scale": 1, "translate": [...]}) are read
// relative to `sceneDir`, as .obj or .ply by extension; vertices are scaled, then translated.
// `context` names the shape for error messages, e.g. "steam.json: obstacles[0].shape"; every
// InputError starts with it: a vector with the wrong number of components for D, box min not
// below max, a zero plane normal, a missing or unreadable mesh file, a mesh in a 2D scene.
template <int D>
std::unique_ptr<Shape<D>> buildShape(const nlohmann::json& shape, const std::filesystem::path& sceneDir,
                                     std::string_view context);

}  // namespace msim::geometry
