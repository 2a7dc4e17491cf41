#include "msim/io/obj.hpp"

#include <gtest/gtest.h>

#include <Eigen/Geometry>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::scratchDir;
using test::writeText;

// Unit cube: quads in every corner notation, one face through negative indices.
constexpr const char* kCube = R"(# unit cube
mtllib cube.mtl
o cube
v 0 0 0
v 1 0 0
v 1 1 0
v 0 1 0
v 0 0 1
v 1 0 1
v 1 1 1
v 0 1 1   # trailing comment
vt 0 0
vn 0 0 -1
usemtl grey
s off
f 1 4 3 2
f 5/1 6/1 7/1 8/1
f 1//1 2//1 6//1 5//1
f 2/1/1 3/1/1 7/1/1 6/1/1
f 3 4 8 7
f -8 -4 -1 -5
)";

TEST(Obj, ReadsCubeWithQuadsAndNegativeIndices) {
  const auto dir = scratchDir();
  writeText(dir / "cube.obj", kCube);
  const auto mesh = readObj(dir / "cube.obj");
  ASSERT_EQ(mesh.vertices.size(), 8u);
  EXPECT_EQ(mesh.vertices[6], Vec3(1, 1, 1));
  EXPECT_EQ(mesh.vertices[7], Vec3(0, 1, 1));
  ASSERT_EQ(mesh.triangles.size(), 12u);
  EXPECT_EQ(mesh.triangles[0], (std::array<int, 3>{0, 3, 2}));
  EXPECT_EQ(mesh.triangles[1], (std::array<int, 3>{0, 2, 1}));
  EXPECT_EQ(mesh.triangles[10], (std::array<int, 3>{0, 4, 7}));  // -8 -4 -1 with 8 vertices
  EXPECT_EQ(mesh.triangles[11], (std::array<int, 3>{0, 7, 3}));

  // Closed and consistently oriented: the signed volume is the cube's.
  double volume = 0.0;
  for (const auto& t : mesh.triangles)
    volume += mesh.vertices[t[0]].dot(mesh.vertices[t[1]].cross(mesh.vertices[t[2]])) / 6.0;
  EXPECT_NEAR(std::abs(volume), 1.0, 1e-12);
}

TEST(Obj, ErrorsNameFileAndLine) {
  const auto dir = scratchDir();
  writeText(dir / "range.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 1 2 4\n");
  expectInputError([&] { readObj(dir / "range.obj"); }, {"range.obj:4", "out of range"});
  writeText(dir / "number.obj", "v 0 0 0\nv 1 x 0\n");
  expectInputError([&] { readObj(dir / "number.obj"); }, {"number.obj:2", "'x'"});
  writeText(dir / "face.obj", "v 0 0 0\nv 1 0 0\nf 1 2\n");
  expectInputError([&] { readObj(dir / "face.obj"); }, {"face.obj:3", "at least 3"});
  writeText(dir / "zero.obj", "v 0 0 0\nv 1 0 0\nv 0 1 0\nf 0 1 2\n");
  expectInputError([&] { readObj(dir / "zero.obj"); }, {"zero.obj:4"});
  expectInputError([&] { readObj(dir / "missing.obj"); }, {"missing.obj"});
}

TEST(Obj, WrittenMeshReadsBackExactly) {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0.1, 0.2, 0.3), Vec3(1.0 / 3.0, -2.5e-4, 7.0), Vec3(-1, 0, 0.125), Vec3(2, 2, 2)};
  mesh.triangles = {{0, 1, 2}, {2, 1, 3}};
  const auto file = scratchDir() / "obj_write_round_trip.obj";
  writeObj(file, mesh);
  const TriangleMesh back = readObj(file);
  ASSERT_EQ(back.vertices.size(), mesh.vertices.size());
  for (std::size_t i = 0; i < mesh.vertices.size(); ++i)
    EXPECT_LT((back.vertices[i] - mesh.vertices[i]).norm(), 1e-8 * (1.0 + mesh.vertices[i].norm()));
  EXPECT_EQ(back.triangles, mesh.triangles);
  mesh.triangles.push_back({0, 1, 4});
  EXPECT_THROW(writeObj(file, mesh), std::invalid_argument);
}

}  // namespace
}  // namespace msim::io
