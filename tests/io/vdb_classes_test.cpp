// msim's VDB files as other tools see them: read back with OpenVDB itself (not msim's reader),
// fog volumes, level sets and velocities carry the class, background, vector type and creator
// that Houdini, Blender and OpenVDB's tools key on; values that are nothing are inactive; the file
// says which scene, frame and time it holds; half-float storage halves the file.
#include <gtest/gtest.h>
#include <openvdb/io/File.h>
#include <openvdb/openvdb.h>
#include <openvdb/tools/Diagnostics.h>

#include <algorithm>
#include <cmath>
#include <cstdio>
#include <memory>

#include "msim/io/vdb.hpp"
#include "msim/version.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::scratchDir;

struct OpenedFile {
  openvdb::MetaMap::Ptr metadata;
  openvdb::GridPtrVecPtr grids;

  template <typename GridT>
  typename GridT::Ptr grid(const std::string& name) const {
    for (const auto& g : *grids)
      if (g->getName() == name) return openvdb::gridPtrCast<GridT>(g);
    return nullptr;
  }
};

OpenedFile openWithOpenVdb(const std::filesystem::path& path) {
  openvdb::initialize();
  openvdb::io::File file(path.string());
  file.open();
  OpenedFile opened{file.getMetadata(), file.getGrids()};
  file.close();
  return opened;
}

TEST(VdbClasses, FogVolumeKeepsOnlyWhatIsAboveTheTolerance) {
  const auto dir = scratchDir();
  Grid<float, 3> density(GridSpec<3>(Vec3(0.0, 0.0, 0.0), 0.1, IVec3(10, 9, 8)));
  std::size_t aboveTolerance = 0, belowTolerance = 0;
  for (std::size_t i = 0; i < density.count(); ++i) {
    switch (i % 4) {
      case 0: density[i] = 0.0f; break;
      case 1: density[i] = 1e-40f; break;  // subnormal: nothing, physically
      case 2: density[i] = 1e-3f, ++belowTolerance; break;
      default: density[i] = 0.5f + 1e-3f * static_cast<float>(i), ++aboveTolerance;
    }
  }
  VdbWriter exact;
  exact.addFogVolume("density", density);
  exact.write(dir / "exact.vdb");
  VdbWriter pruned(VdbWriteOptions{.fogTolerance = 1e-2f});
  pruned.addFogVolume("density", density);
  pruned.write(dir / "pruned.vdb");

  const auto exactGrid = openWithOpenVdb(dir / "exact.vdb").grid<openvdb::FloatGrid>("density");
  ASSERT_TRUE(exactGrid);
  EXPECT_EQ(exactGrid->getGridClass(), openvdb::GRID_FOG_VOLUME);
  EXPECT_EQ(exactGrid->background(), 0.0f);
  EXPECT_EQ(exactGrid->getCreator(), std::string("msim ") + kVersion);
  EXPECT_EQ(exactGrid->activeVoxelCount(), aboveTolerance + belowTolerance);
  const auto prunedGrid = openWithOpenVdb(dir / "pruned.vdb").grid<openvdb::FloatGrid>("density");
  ASSERT_TRUE(prunedGrid);
  EXPECT_EQ(prunedGrid->activeVoxelCount(), aboveTolerance);

  const Grid<float, 3> back = readFloatGrid(dir / "pruned.vdb", "density");
  for (std::size_t i = 0; i < density.count(); ++i) ASSERT_EQ(back[i], i % 4 == 3 ? density[i] : 0.0f) << i;
}

TEST(VdbClasses, SignedDistanceBecomesANarrowBandLevelSet) {
  const auto dir = scratchDir();
  const double dx = 2.0 / 32.0;
  Grid<float, 3> distance(GridSpec<3>(Vec3::Zero(), dx, IVec3(32, 32, 32)));
  for (int k = 0; k < 32; ++k)
    for (int j = 0; j < 32; ++j)
      for (int i = 0; i < 32; ++i)
        distance(IVec3(i, j, k)) =
            static_cast<float>((distance.spec().cellCenter(IVec3(i, j, k)) - Vec3(1.0, 1.0, 1.0)).norm() - 0.6);
  VdbWriter writer;
  writer.addLevelSet("obstacle_distance", distance);
  writer.write(dir / "sphere.vdb");

  const auto grid = openWithOpenVdb(dir / "sphere.vdb").grid<openvdb::FloatGrid>("obstacle_distance");
  ASSERT_TRUE(grid);
  const float band = static_cast<float>(3 * dx);
  EXPECT_EQ(grid->getGridClass(), openvdb::GRID_LEVEL_SET);
  EXPECT_EQ(grid->background(), band);
  const auto inBand = std::count_if(distance.data().begin(), distance.data().end(),
                                    [&](float v) { return std::abs(v) < band; });
  EXPECT_EQ(grid->activeVoxelCount(), static_cast<openvdb::Index64>(inBand));
  // OpenVDB's own level-set diagnostics: class, uniform voxels, background, inactive values of
  // +-background, finite values, no active values beyond the band, and |grad phi| = 1 (Eikonal).
  EXPECT_EQ(openvdb::tools::checkLevelSet(*grid, 9), "");
  const auto access = grid->getConstAccessor();
  EXPECT_EQ(access.getValue(openvdb::Coord(16, 16, 16)), -band);  // deep inside, inactive
  EXPECT_EQ(access.getValue(openvdb::Coord(0, 0, 0)), band);

  const Grid<float, 3> back = readFloatGrid(dir / "sphere.vdb", "obstacle_distance");
  for (std::size_t i = 0; i < distance.count(); ++i) ASSERT_EQ(back[i], std::clamp(distance[i], -band, band)) << i;
}

TEST(VdbClasses, VelocityIsAContravariantVectorAndTheFileSaysWhatItHolds) {
  const auto dir = scratchDir();
  const GridSpec<3> spec(Vec3::Zero(), 0.25, IVec3(4, 4, 4));
  Grid<Vecf<3>, 3> velocity(spec, Vecf<3>(1.0f, -2.0f, 0.5f));
  VdbWriter writer;
  writer.addVectorGrid("vel", velocity);
  const VdbFrameInfo frame{"tiny", 7, 0.875};
  writer.write(dir / "frame.vdb", &frame);

  const OpenedFile file = openWithOpenVdb(dir / "frame.vdb");
  const auto vel = file.grid<openvdb::Vec3SGrid>("vel");
  ASSERT_TRUE(vel);
  EXPECT_EQ(vel->getVectorType(), openvdb::VEC_CONTRAVARIANT_RELATIVE);
  EXPECT_EQ(vel->activeVoxelCount(), 64u);
  const openvdb::MetaMap& meta = *file.metadata;
  EXPECT_EQ(meta.metaValue<std::string>("msim_scene"), "tiny");
  EXPECT_EQ(meta.metaValue<openvdb::Int32>("msim_frame"), 7);
  EXPECT_EQ(meta.metaValue<double>("msim_time"), 0.875);
  EXPECT_EQ(meta.metaValue<std::string>("msim_version"), kVersion);
  EXPECT_NE(meta.metaValue<std::string>("msim_units").find("SI"), std::string::npos);
}

TEST(VdbClasses, HalfFloatStorageHalvesTheFileAndRoundsTo11Bits) {
  const auto dir = scratchDir();
  Grid<float, 3> density(GridSpec<3>(Vec3::Zero(), 0.1, IVec3(40, 40, 40)));
  for (std::size_t i = 0; i < density.count(); ++i) density[i] = 0.1f + std::sin(0.37f * static_cast<float>(i)) * 0.05f;
  VdbWriter full;
  full.addFogVolume("density", density);
  full.write(dir / "full.vdb");
  VdbWriter half(VdbWriteOptions{.halfFloat = true});
  half.addFogVolume("density", density);
  half.write(dir / "half.vdb");

  const double ratio = double(std::filesystem::file_size(dir / "half.vdb")) / double(std::filesystem::file_size(dir / "full.vdb"));
  EXPECT_LT(ratio, 0.6);
  EXPECT_GT(ratio, 0.4);
  const auto grid = openWithOpenVdb(dir / "half.vdb").grid<openvdb::FloatGrid>("density");
  ASSERT_TRUE(grid);
  EXPECT_TRUE(grid->saveFloatAsHalf());
  const Grid<float, 3> back = readFloatGrid(dir / "half.vdb", "density");
  for (std::size_t i = 0; i < density.count(); ++i)
    ASSERT_NEAR(back[i], density[i], density[i] * std::ldexp(1.0f, -11)) << i;
}

// OpenVDB's command-line tool vdb_print (Debian's libopenvdb-tools, which install-deps.sh
// installs) lists the grids with their classes.
TEST(VdbClasses, OpenVdbsPrintToolShowsTheClasses) {
  if (std::system("command -v vdb_print > /dev/null 2>&1") != 0) GTEST_SKIP() << "vdb_print is not installed";
  const auto dir = scratchDir();
  Grid<float, 3> field(GridSpec<3>(Vec3::Zero(), 0.5, IVec3(8, 8, 8)), 0.25f);
  field[0] = -1.0f;
  VdbWriter writer;
  writer.addFogVolume("density", field);
  writer.addLevelSet("obstacle_distance", field);
  writer.write(dir / "frame.vdb");
  const std::string command = "vdb_print -l " + (dir / "frame.vdb").string() + " 2>&1";
  std::unique_ptr<FILE, int (*)(FILE*)> pipe(popen(command.c_str(), "r"), pclose);
  ASSERT_TRUE(pipe);
  std::string output;
  char buffer[4096];
  while (std::size_t n = std::fread(buffer, 1, sizeof buffer, pipe.get())) output.append(buffer, n);
  EXPECT_NE(output.find("fog volume"), std::string::npos) << output;
  EXPECT_NE(output.find("level set"), std::string::npos) << output;
}

}  // namespace
}  // namespace msim::io
