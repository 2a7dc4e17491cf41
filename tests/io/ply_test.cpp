#include "msim/io/ply.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::readBytes;
using test::scratchDir;
using test::writeText;

PointCloud randomCloud(std::size_t n) {
  std::mt19937 rng(7);
  std::uniform_real_distribution<float> u(-100.0f, 100.0f);
  PointCloud cloud;
  cloud.positions.resize(n);
  for (auto& p : cloud.positions) p = Vecf<3>(u(rng), u(rng), u(rng) * 1e-6f);
  cloud.attributes.push_back({"density", std::vector<float>(n)});
  cloud.attributes.push_back({"temperature", std::vector<float>(n)});
  for (std::size_t i = 0; i < n; ++i) {
    cloud.attributes[0].values[i] = u(rng);
    cloud.attributes[1].values[i] = i % 5 == 0 ? 0.0f : 1.0f / static_cast<float>(i + 1);
  }
  return cloud;
}

void expectBitEqual(const PointCloud& a, const PointCloud& b) {
  ASSERT_EQ(a.positions.size(), b.positions.size());
  EXPECT_EQ(std::memcmp(a.positions.data(), b.positions.data(), a.positions.size() * sizeof(Vecf<3>)), 0);
  ASSERT_EQ(a.attributes.size(), b.attributes.size());
  for (std::size_t k = 0; k < a.attributes.size(); ++k) {
    EXPECT_EQ(a.attributes[k].name, b.attributes[k].name);
    ASSERT_EQ(a.attributes[k].values.size(), b.attributes[k].values.size());
    EXPECT_EQ(std::memcmp(a.attributes[k].values.data(), b.attributes[k].values.data(),
                          a.attributes[k].values.size() * sizeof(float)),
              0);
  }
}

TriangleMesh tetrahedron() {
  TriangleMesh mesh;
  mesh.vertices = {Vec3(0, 0, 0), Vec3(1.0 / 3.0, 0, 0), Vec3(0, 1e-7, 0), Vec3(0.1, 0.2, -12345.678)};
  mesh.triangles = {{0, 2, 1}, {0, 1, 3}, {1, 2, 3}, {0, 3, 2}};
  return mesh;
}

class PlyEncodings : public ::testing::TestWithParam<PlyEncoding> {};

TEST_P(PlyEncodings, PointsRoundTripBitEqual) {
  const auto dir = scratchDir();
  const PointCloud cloud = randomCloud(500);
  writePlyPoints(dir / "p.ply", cloud, GetParam());
  const PointCloud back = readPlyPoints(dir / "p.ply");
  expectBitEqual(cloud, back);
  writePlyPoints(dir / "q.ply", back, GetParam());
  EXPECT_EQ(readBytes(dir / "p.ply"), readBytes(dir / "q.ply"));
}

TEST_P(PlyEncodings, DoubleMeshRoundTripIsExact) {
  const auto dir = scratchDir();
  const auto mesh = tetrahedron();
  const std::vector<PointAttribute> attrs{{"phi", {0.5f, -1.0f, 3e-30f, 7.0f}}};
  writePlyMesh(dir / "m.ply", mesh, attrs, {GetParam(), PlyPositionType::Float64});
  const PlyMesh back = readPlyMesh(dir / "m.ply");
  EXPECT_EQ(back.mesh.vertices, mesh.vertices);
  EXPECT_EQ(back.mesh.triangles, mesh.triangles);
  ASSERT_EQ(back.vertexAttributes.size(), 1u);
  EXPECT_EQ(back.vertexAttributes[0].name, "phi");
  EXPECT_EQ(back.vertexAttributes[0].values, attrs[0].values);
}

TEST_P(PlyEncodings, FloatMeshIsStableAfterFirstRounding) {
  const auto dir = scratchDir();
  writePlyMesh(dir / "a.ply", tetrahedron(), {}, {GetParam(), PlyPositionType::Float32});
  const PlyMesh first = readPlyMesh(dir / "a.ply");
  EXPECT_EQ(first.mesh.vertices[1].x(), static_cast<double>(static_cast<float>(1.0 / 3.0)));
  writePlyMesh(dir / "b.ply", first.mesh, {}, {GetParam(), PlyPositionType::Float32});
  EXPECT_EQ(readBytes(dir / "a.ply"), readBytes(dir / "b.ply"));
  EXPECT_EQ(readPlyMesh(dir / "b.ply").mesh.vertices, first.mesh.vertices);
}

INSTANTIATE_TEST_SUITE_P(Ply, PlyEncodings, ::testing::Values(PlyEncoding::BinaryLittleEndian, PlyEncoding::Ascii));

TEST(Ply, BinaryHeaderIsStandard) {
  const auto dir = scratchDir();
  writePlyMesh(dir / "m.ply", tetrahedron());
  const std::string bytes = readBytes(dir / "m.ply");
  EXPECT_EQ(bytes.rfind("ply\nformat binary_little_endian 1.0\n", 0), 0u);
  EXPECT_NE(bytes.find("property float x\n"), std::string::npos);
  EXPECT_NE(bytes.find("element face 4\nproperty list uchar int vertex_indices\nend_header\n"), std::string::npos);
}

TEST(Ply, ReadsForeignAsciiWithQuadsAndMixedTypes) {
  const auto dir = scratchDir();
  writeText(dir / "quad.ply",
            "ply\r\nformat ascii 1.0\r\ncomment from elsewhere\r\nelement vertex 4\r\n"
            "property double x\r\nproperty double y\r\nproperty double z\r\nproperty uchar red\r\n"
            "element face 1\r\nproperty list uchar uint vertex_index\r\nend_header\r\n"
            "0 0 0 255\r\n1 0 0 0\r\n1 1 0 7\r\n0 1 0.5 1\r\n4 0 1 2 3\r\n");
  const PlyMesh m = readPlyMesh(dir / "quad.ply");
  EXPECT_EQ(m.mesh.vertices[3], Vec3(0, 1, 0.5));
  EXPECT_EQ(m.mesh.triangles, (std::vector<std::array<int, 3>>{{0, 1, 2}, {0, 2, 3}}));
  ASSERT_EQ(m.vertexAttributes.size(), 1u);
  EXPECT_EQ(m.vertexAttributes[0].values, (std::vector<float>{255, 0, 7, 1}));
}

TEST(Ply, MalformedFilesThrowInputErrorNamingFileAndLine) {
  const auto dir = scratchDir();
  const std::string header =
      "ply\nformat ascii 1.0\nelement vertex 2\nproperty float x\nproperty float y\nproperty float z\nend_header\n";
  writeText(dir / "badvalue.ply", header + "0 0 0\n1 zz 0\n");
  expectInputError([&] { readPlyPoints(dir / "badvalue.ply"); }, {"badvalue.ply:9", "'zz'"});
  writeText(dir / "short.ply", header + "0 0 0\n");
  expectInputError([&] { readPlyPoints(dir / "short.ply"); }, {"short.ply", "truncated"});
  writeText(dir / "keyword.ply", "ply\nformat ascii 1.0\nelemnt vertex 2\n");
  expectInputError([&] { readPlyPoints(dir / "keyword.ply"); }, {"keyword.ply:3", "elemnt"});
  writeText(dir / "notply.ply", "solid cube\n");
  expectInputError([&] { readPlyPoints(dir / "notply.ply"); }, {"notply.ply", "not a PLY"});
  writeText(dir / "nofaces.ply", header + "0 0 0\n1 1 1\n");
  expectInputError([&] { readPlyMesh(dir / "nofaces.ply"); }, {"nofaces.ply", "'face'"});
  expectInputError([&] { readPlyPoints(dir / "missing.ply"); }, {"missing.ply"});
}

TEST(Ply, TruncatedBinaryThrowsInputError) {
  const auto dir = scratchDir();
  writePlyPoints(dir / "p.ply", randomCloud(50));
  std::string bytes = readBytes(dir / "p.ply");
  bytes.resize(bytes.size() - 3);
  writeText(dir / "cut.ply", bytes);
  expectInputError([&] { readPlyPoints(dir / "cut.ply"); }, {"cut.ply", "truncated"});
}

TEST(Ply, OutOfRangeFaceIndexThrowsInputError) {
  const auto dir = scratchDir();
  writeText(dir / "f.ply",
            "ply\nformat ascii 1.0\nelement vertex 3\nproperty float x\nproperty float y\nproperty float z\n"
            "element face 1\nproperty list uchar int vertex_indices\nend_header\n0 0 0\n1 0 0\n0 1 0\n3 0 1 3\n");
  expectInputError([&] { readPlyMesh(dir / "f.ply"); }, {"f.ply", "vertex 3"});
}

}  // namespace
}  // namespace msim::io
