#include "msim/geometry/shape_factory.hpp"

#include <gtest/gtest.h>

#include <filesystem>
#include <fstream>
#include <string>

#include "msim/core/error.hpp"

namespace msim::geometry {
namespace {

using nlohmann::json;

const std::filesystem::path kSceneDir = std::filesystem::path(MSIM_TEST_TMP) / "geometry_scene";

template <int D>
std::string buildError(const json& shape) {
  try {
    buildShape<D>(shape, kSceneDir, "scene.json: obstacles[0].shape");
  } catch (const InputError& e) {
    return e.what();
  }
  return "";
}

TEST(BuildShape, AnalyticShapesIn3D) {
  const auto sphere = buildShape<3>(json::parse(R"({"type": "sphere", "center": [1, 0, 0], "radius": 0.5})"), kSceneDir, "s");
  EXPECT_DOUBLE_EQ(sphere->distance(Vec3(3, 0, 0)), 1.5);
  const auto box = buildShape<3>(json::parse(R"({"type": "box", "min": [0, 0, 0], "max": [1, 1, 1]})"), kSceneDir, "s");
  EXPECT_DOUBLE_EQ(box->distance(Vec3(2, 2, 1)), std::sqrt(2.0));
  const auto capsule = buildShape<3>(json::parse(R"({"type": "capsule", "a": [0,0,0], "b": [0,1,0], "radius": 0.1})"),
                                     kSceneDir, "s");
  EXPECT_DOUBLE_EQ(capsule->distance(Vec3(1, 0.5, 0)), 0.9);
  const auto plane = buildShape<3>(json::parse(R"({"type": "plane", "point": [0,1,0], "normal": [0,1,0]})"), kSceneDir, "s");
  EXPECT_DOUBLE_EQ(plane->distance(Vec3(0, 0, 0)), -1.0);
}

TEST(BuildShape, AnalyticShapesIn2D) {
  const auto circle = buildShape<2>(json::parse(R"({"type": "sphere", "center": [0, 0], "radius": 1})"), kSceneDir, "s");
  EXPECT_DOUBLE_EQ(circle->distance(Vec2(3, 4)), 4.0);
}

TEST(BuildShape, InvalidGeometryIsNamed) {
  EXPECT_EQ(buildError<2>(json::parse(R"({"type": "sphere", "center": [0, 0, 0], "radius": 1})")),
            "scene.json: obstacles[0].shape: 'center' has 3 components; a 2D scene needs 2");
  EXPECT_NE(buildError<3>(json::parse(R"({"type": "box", "min": [0, 0, 0], "max": [1, 0, 1]})")).find("below 'max'"),
            std::string::npos);
  EXPECT_NE(buildError<3>(json::parse(R"({"type": "plane", "point": [0,0,0], "normal": [0,0,0]})")).find("zero"),
            std::string::npos);
  EXPECT_NE(buildError<2>(json::parse(R"({"type": "mesh", "file": "a.obj", "scale": 1, "translate": [0,0,0]})"))
                .find("mesh shapes need a 3D scene"),
            std::string::npos);
}

TEST(BuildShape, MeshIsLoadedRelativeToSceneDirScaledAndTranslated) {
  std::filesystem::create_directories(kSceneDir / "meshes");
  {
    std::ofstream obj(kSceneDir / "meshes" / "cube.obj");
    obj << "v 0 0 0\nv 1 0 0\nv 0 1 0\nv 1 1 0\nv 0 0 1\nv 1 0 1\nv 0 1 1\nv 1 1 1\n"
           "f 1 3 4\nf 1 4 2\nf 5 6 8\nf 5 8 7\nf 1 2 6\nf 1 6 5\nf 3 7 8\nf 3 8 4\nf 1 5 7\nf 1 7 3\nf 2 4 8\nf 2 8 6\n";
  }
  const auto mesh = buildShape<3>(
      json::parse(R"({"type": "mesh", "file": "meshes/cube.obj", "scale": 2, "translate": [10, 0, 0]})"), kSceneDir, "s");
  // Cube [10,12] x [0,2] x [0,2].
  EXPECT_NEAR(mesh->distance(Vec3(11, 1, 1)), -1.0, 1e-12);
  EXPECT_NEAR(mesh->distance(Vec3(13, 1, 1)), 1.0, 1e-12);
  EXPECT_EQ(mesh->bounds().max, Vec3(12, 2, 2));
}

TEST(BuildShape, MissingMeshFileNamesKeyPathAndFile) {
  const std::string msg = buildError<3>(json::parse(R"({"type": "mesh", "file": "nope.obj", "scale": 1, "translate": [0,0,0]})"));
  EXPECT_EQ(msg.rfind("scene.json: obstacles[0].shape: mesh file '", 0), 0u) << msg;
  EXPECT_NE(msg.find((kSceneDir / "nope.obj").string()), std::string::npos) << msg;
}

}  // namespace
}  // namespace msim::geometry
