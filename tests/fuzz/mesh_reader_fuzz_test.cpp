// Fuzzing the OBJ and PLY readers with mutations of a shipped mesh and of small PLY files in
// both encodings: every case reads or is refused with an InputError naming the file.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>

#include "fuzz_case.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "mutator.hpp"

namespace msim::fuzz {
namespace {

// A small closed mesh: an octahedron with a per-vertex attribute.
TriangleMesh octahedron() {
  TriangleMesh m;
  m.vertices = {Vec3(1, 0, 0), Vec3(-1, 0, 0), Vec3(0, 1, 0), Vec3(0, -1, 0), Vec3(0, 0, 1), Vec3(0, 0, -1)};
  m.triangles = {{0, 2, 4}, {2, 1, 4}, {1, 3, 4}, {3, 0, 4}, {2, 0, 5}, {1, 2, 5}, {3, 1, 5}, {0, 3, 5}};
  return m;
}

io::PointCloud spiral(int n) {
  io::PointCloud cloud;
  io::PointAttribute speed{"speed", {}};
  for (int i = 0; i < n; ++i) {
    const float t = 0.3f * float(i);
    cloud.positions.push_back(Vecf<3>(std::cos(t), std::sin(t), 0.05f * float(i)));
    speed.values.push_back(0.5f * float(i));
  }
  cloud.attributes.push_back(speed);
  return cloud;
}

template <typename Read>
Outcomes fuzzFile(const std::string& name, const std::string& original, const std::string& extension, int cases,
                  std::uint64_t seed, bool text, Read read) {
  const auto dir = fuzzScratch(name);
  Mutator mutator(seed);
  Outcomes outcomes;
  for (int k = 0; k < cases; ++k) {
    const std::string caseName = name + "_" + std::to_string(k);
    const auto input = dir / (caseName + extension);
    writeBytes(input, text ? mutator.mutateText(original) : mutator.mutateBytes(original));
    runCase(caseName, input, [&] { read(input); }, outcomes);
  }
  std::printf("%s: %d cases, %d read, %d refused with InputError\n", name.c_str(), cases, outcomes.accepted,
              outcomes.rejected);
  return outcomes;
}

TEST(MeshReaderFuzz, MutatedObjFilesReadOrFailWithInputError) {
  const std::string log = readBytes(std::filesystem::path(MSIM_SOURCE_DIR) / "scenes" / "meshes" / "log.obj");
  ASSERT_FALSE(log.empty());
  const Outcomes o = fuzzFile("obj", log, ".obj", 600, 11, /*text=*/true, [](const auto& p) { io::readObj(p); });
  EXPECT_GT(o.rejected, 0);
  EXPECT_GT(o.accepted, 0);
}

TEST(MeshReaderFuzz, MutatedBinaryPlyFilesReadOrFailWithInputError) {
  const auto dir = fuzzScratch("ply_sources_binary");
  const TriangleMesh mesh = octahedron();
  const std::vector<io::PointAttribute> heat{{"heat", {0, 1, 2, 3, 4, 5}}};
  io::writePlyMesh(dir / "mesh.ply", mesh, heat);
  io::writePlyPoints(dir / "points.ply", spiral(24));
  const Outcomes meshes = fuzzFile("ply_mesh_binary", readBytes(dir / "mesh.ply"), ".ply", 600, 12, false,
                                   [](const auto& p) { io::readPlyMesh(p); });
  const Outcomes points = fuzzFile("ply_points_binary", readBytes(dir / "points.ply"), ".ply", 400, 13, false,
                                   [](const auto& p) { io::readPlyPoints(p); });
  EXPECT_GT(meshes.rejected + points.rejected, 0);
  EXPECT_GT(meshes.accepted + points.accepted, 0);
}

TEST(MeshReaderFuzz, MutatedAsciiPlyFilesReadOrFailWithInputError) {
  const auto dir = fuzzScratch("ply_sources_ascii");
  io::writePlyMesh(dir / "mesh.ply", octahedron(), {}, {io::PlyEncoding::Ascii});
  io::writePlyPoints(dir / "points.ply", spiral(24), io::PlyEncoding::Ascii);
  const Outcomes meshes = fuzzFile("ply_mesh_ascii", readBytes(dir / "mesh.ply"), ".ply", 500, 14, true,
                                   [](const auto& p) { io::readPlyMesh(p); });
  const Outcomes points = fuzzFile("ply_points_ascii", readBytes(dir / "points.ply"), ".ply", 300, 15, true,
                                   [](const auto& p) { io::readPlyPoints(p); });
  EXPECT_GT(meshes.rejected + points.rejected, 0);
  EXPECT_GT(meshes.accepted + points.accepted, 0);
}

}  // namespace
}  // namespace msim::fuzz
