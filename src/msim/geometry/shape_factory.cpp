#include "msim/geometry/shape_factory.hpp"

#include <string>

#include "msim/core/error.hpp"
#include "msim/geometry/analytic_shapes.hpp"
#include "msim/geometry/mesh_shape.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"

namespace msim::geometry {
namespace {

[[noreturn]] void fail(std::string_view context, const std::string& message) {
  throw InputError(std::string(context) + ": " + message);
}

template <int D>
Vec<D> readVector(const nlohmann::json& shape, const char* key, std::string_view context) {
  const nlohmann::json& v = shape.at(key);
  if (v.size() != static_cast<std::size_t>(D))
    fail(context, std::string("'") + key + "' has " + std::to_string(v.size()) + " components; a " + std::to_string(D) +
                      "D scene needs " + std::to_string(D));
  Vec<D> out;
  for (int a = 0; a < D; ++a) out[a] = v[a].get<double>();
  return out;
}

TriangleMesh readMeshFile(const nlohmann::json& shape, const std::filesystem::path& sceneDir, std::string_view context) {
  const std::filesystem::path file = sceneDir / shape.at("file").get<std::string>();
  std::error_code ec;
  if (!std::filesystem::is_regular_file(file, ec)) fail(context, "mesh file '" + file.string() + "' not found");
  std::string extension = file.extension().string();
  for (char& c : extension) c = static_cast<char>(std::tolower(static_cast<unsigned char>(c)));
  TriangleMesh mesh;
  if (extension == ".obj") {
    mesh = io::readObj(file);
  } else if (extension == ".ply") {
    mesh = io::readPlyMesh(file).mesh;
  } else {
    fail(context, "mesh file '" + file.string() + "' must end in .obj or .ply");
  }
  if (mesh.triangles.empty()) fail(context, "mesh file '" + file.string() + "' has no triangles");
  const double scale = shape.at("scale").get<double>();
  const Vec3 translate = readVector<3>(shape, "translate", context);
  for (Vec3& v : mesh.vertices) v = v * scale + translate;
  return mesh;
}

}  // namespace

template <int D>
std::unique_ptr<Shape<D>> buildShape(const nlohmann::json& shape, const std::filesystem::path& sceneDir,
                                     std::string_view context) {
  const std::string type = shape.at("type").get<std::string>();
  if (type == "sphere") return std::make_unique<Sphere<D>>(readVector<D>(shape, "center", context), shape.at("radius").get<double>());
  if (type == "box") {
    const Vec<D> lo = readVector<D>(shape, "min", context);
    const Vec<D> hi = readVector<D>(shape, "max", context);
    if (!(lo.array() < hi.array()).all()) fail(context, "box 'min' must be below 'max' on every axis");
    return std::make_unique<Box<D>>(lo, hi);
  }
  if (type == "capsule")
    return std::make_unique<Capsule<D>>(readVector<D>(shape, "a", context), readVector<D>(shape, "b", context),
                                        shape.at("radius").get<double>());
  if (type == "cylinder") {
    const Vec<D> a = readVector<D>(shape, "a", context), b = readVector<D>(shape, "b", context);
    if (!((b - a).norm() > 0.0)) fail(context, "cylinder ends 'a' and 'b' must differ");
    return std::make_unique<Cylinder<D>>(a, b, shape.at("radius").get<double>());
  }
  if (type == "plane") {
    const Vec<D> normal = readVector<D>(shape, "normal", context);
    if (normal.norm() == 0.0) fail(context, "plane 'normal' must not be zero");
    return std::make_unique<Plane<D>>(readVector<D>(shape, "point", context), normal);
  }
  if (type == "mesh") {
    if constexpr (D == 3) {
      return std::make_unique<MeshShape>(readMeshFile(shape, sceneDir, context));
    } else {
      fail(context, "mesh shapes need a 3D scene");
    }
  }
  fail(context, "unknown shape type '" + type + "'");
}

template std::unique_ptr<Shape<2>> buildShape<2>(const nlohmann::json&, const std::filesystem::path&, std::string_view);
template std::unique_ptr<Shape<3>> buildShape<3>(const nlohmann::json&, const std::filesystem::path&, std::string_view);

}  // namespace msim::geometry
