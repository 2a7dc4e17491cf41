#include "msim/io/vdb.hpp"

#include <gtest/gtest.h>

#include <cstring>
#include <random>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::scratchDir;
using test::writeText;

// Random values with plenty of exact zeros (which become inactive), negatives and a -0.
Grid<float, 3> randomScalarGrid() {
  const GridSpec<3> spec(Vec3(-0.3, 1.25, 7.0), 0.1, IVec3(19, 10, 13));  // not multiples of the leaf size
  Grid<float, 3> g(spec);
  std::mt19937 rng(1);
  std::uniform_real_distribution<float> u(-5.0f, 5.0f);
  for (std::size_t i = 0; i < g.count(); ++i) g[i] = i % 3 == 0 ? 0.0f : u(rng);
  g[1] = -0.0f;
  g[2] = 1e-40f;  // denormal
  return g;
}

bool bitEqual(const std::vector<float>& a, const std::vector<float>& b) {
  return a.size() == b.size() && std::memcmp(a.data(), b.data(), a.size() * sizeof(float)) == 0;
}

TEST(Vdb, FloatGridRoundTripIsBitEqual) {
  const auto dir = scratchDir();
  const auto density = randomScalarGrid();
  Grid<float, 3> empty(GridSpec<3>(Vec3::Zero(), 0.5, IVec3(4, 4, 4)));
  VdbWriter writer;
  writer.addFloatGrid("density", density);
  writer.addFloatGrid("empty", empty);
  writer.write(dir / "f.vdb");
  EXPECT_EQ(listVdbGrids(dir / "f.vdb"), (std::vector<std::string>{"density", "empty"}));

  const auto back = readFloatGrid(dir / "f.vdb", "density");
  EXPECT_EQ(back.spec(), density.spec());
  EXPECT_TRUE(back.sameLayout(density));
  EXPECT_TRUE(bitEqual(back.data(), density.data()));
  const auto emptyBack = readFloatGrid(dir / "f.vdb", "empty");
  EXPECT_EQ(emptyBack.spec(), empty.spec());
  EXPECT_TRUE(bitEqual(emptyBack.data(), empty.data()));
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

TEST(Vdb, ToleranceDropsSmallValues) {
  const auto dir = scratchDir();
  Grid<float, 3> g(GridSpec<3>(Vec3::Zero(), 1.0, IVec3(3, 1, 1)));
  g[0] = 0.01f;
  g[1] = -0.5f;
  g[2] = -0.02f;
  VdbWriter writer;
  writer.addFloatGrid("d", g, 0.05f);
  writer.write(dir / "t.vdb");
  EXPECT_EQ(readFloatGrid(dir / "t.vdb", "d").data(), (std::vector<float>{0.0f, -0.5f, 0.0f}));
}

TEST(Vdb, TwoDimensionalGridBecomesOneVoxelThick) {
  const auto dir = scratchDir();
  Grid<float, 2> g(GridSpec<2>(Vec2(1.0, -2.0), 0.25, IVec2(5, 3)));
  for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(i) - 4.5f;
  VdbWriter writer;
  writer.addFloatGrid("smoke", g);
  writer.write(dir / "2d.vdb");
  const auto back = readFloatGrid(dir / "2d.vdb", "smoke");
  EXPECT_EQ(back.spec(), GridSpec<3>(Vec3(1.0, -2.0, 0.0), 0.25, IVec3(5, 3, 1)));
  EXPECT_TRUE(bitEqual(back.data(), g.data()));
}

TEST(Vdb, VectorGridsRoundTrip) {
  const auto dir = scratchDir();
  const GridSpec<3> spec(Vec3(0.5, 0.0, -1.0), 0.2, IVec3(9, 4, 3));
  Grid<Vecf<3>, 3> v(spec, Vecf<3>::Zero());
  std::mt19937 rng(3);
  std::uniform_real_distribution<float> u(-2.0f, 2.0f);
  for (std::size_t i = 0; i < v.count(); i += 2) v[i] = Vecf<3>(u(rng), 0.0f, u(rng));
  Grid<Vec3, 3> vd(spec, Vec3::Zero());
  for (std::size_t i = 0; i < vd.count(); ++i) vd[i] = Vec3(0.1 * i, -1.0, 1.0 / 3.0);

  MacGrid<3> mac(spec);
  for (int a = 0; a < 3; ++a)
    for (std::size_t i = 0; i < mac.component(a).count(); ++i) mac.component(a)[i] = static_cast<float>(a + 1) * (i % 7);

  VdbWriter writer;
  writer.addVectorGrid("v", v);
  writer.addVectorGrid("vd", vd);
  writer.addVectorGrid("vel", mac);
  writer.write(dir / "v.vdb");

  const auto vBack = readVectorGrid(dir / "v.vdb", "v");
  EXPECT_EQ(vBack.spec(), spec);
  EXPECT_EQ(vBack.data(), v.data());
  const auto vdBack = readVectorGrid(dir / "v.vdb", "vd");
  for (std::size_t i = 0; i < vd.count(); ++i) EXPECT_EQ(vdBack[i], vd[i].cast<float>());

  const auto velBack = readVectorGrid(dir / "v.vdb", "vel");
  EXPECT_EQ(velBack.spec(), spec);
  const IVec3 c(4, 2, 1);
  for (int a = 0; a < 3; ++a) {
    IVec3 upper = c;
    upper[a] += 1;
    EXPECT_EQ(velBack(c)[a], 0.5f * (mac.component(a)(c) + mac.component(a)(upper)));
  }
}

TEST(Vdb, PointsRoundTripBitEqualInOrder) {
  const auto dir = scratchDir();
  std::mt19937 rng(5);
  std::uniform_real_distribution<float> u(-3.0f, 40.0f);
  PointCloud cloud;
  const std::size_t n = 2000;
  for (std::size_t i = 0; i < n; ++i) cloud.positions.emplace_back(u(rng), u(rng) * 1e-3f, u(rng));
  cloud.positions[0] = Vecf<3>(0.0f, -0.0f, 1e-30f);
  cloud.attributes.push_back({"temperature", {}});
  cloud.attributes.push_back({"age", {}});
  for (std::size_t i = 0; i < n; ++i) {
    cloud.attributes[0].values.push_back(u(rng));
    cloud.attributes[1].values.push_back(static_cast<float>(i));
  }
  VdbWriter writer;
  writer.addPoints("particles", cloud, 0.3);  // rounded to 0.25 internally
  writer.write(dir / "p.vdb");

  const PointCloud back = readPoints(dir / "p.vdb", "particles");
  ASSERT_EQ(back.positions.size(), n);
  for (std::size_t i = 0; i < n; ++i)
    ASSERT_EQ(std::memcmp(back.positions[i].data(), cloud.positions[i].data(), sizeof(Vecf<3>)), 0)
        << "point " << i << ": " << back.positions[i].transpose() << " vs " << cloud.positions[i].transpose();
  ASSERT_EQ(back.attributes.size(), 2u);
  EXPECT_EQ(back.attributes[0].name, "temperature");
  EXPECT_TRUE(bitEqual(back.attributes[0].values, cloud.attributes[0].values));
  EXPECT_EQ(back.attributes[1].name, "age");
  EXPECT_TRUE(bitEqual(back.attributes[1].values, cloud.attributes[1].values));
}

TEST(Vdb, GridsAndPointsShareOneFile) {
  const auto dir = scratchDir();
  PointCloud cloud;
  cloud.positions = {Vecf<3>(1, 2, 3), Vecf<3>(-1, 0.5f, 0)};
  VdbWriter writer;
  writer.addFloatGrid("density", randomScalarGrid());
  writer.addPoints("particles", cloud, 1.0);
  writer.write(dir / "frame.vdb");
  EXPECT_EQ(readPoints(dir / "frame.vdb", "particles").positions, cloud.positions);
  EXPECT_EQ(readFloatGrid(dir / "frame.vdb", "density").data(), randomScalarGrid().data());
  EXPECT_THROW(writer.addFloatGrid("density", randomScalarGrid()), std::invalid_argument);
}

TEST(Vdb, NumbersRoundTripExactlyBesideTheFrameMetadata) {
  // A resumed run's state besides the grids (volume control's integrator, counters): doubles
  // back bit for bit, next to the frame's own metadata; a name asked for that is not there is an
  // input error naming the file, a repeated one refused when written.
  const auto dir = scratchDir();
  VdbWriter writer;
  writer.addFloatGrid("density", randomScalarGrid());
  writer.addNumber("target", 0.1 + 0.2);
  writer.addNumber("integral", -1e-300);
  EXPECT_THROW(writer.addNumber("target", 1.0), std::invalid_argument);
  EXPECT_THROW(writer.addNumber("", 1.0), std::invalid_argument);
  const VdbFrameInfo info{"scene", 3, 0.25};
  writer.write(dir / "f.vdb", &info);
  const VdbFile file(dir / "f.vdb", VdbProvenance::MsimRun);
  EXPECT_EQ(file.number("target"), 0.1 + 0.2);
  EXPECT_EQ(file.number("integral"), -1e-300);
  expectInputError([&] { (void)file.number("leak"); }, {"f.vdb", "'leak'"});
}

TEST(Vdb, ReadErrorsAreInputErrorsNamingTheFile) {
  const auto dir = scratchDir();
  VdbWriter writer;
  writer.addFloatGrid("density", randomScalarGrid());
  writer.write(dir / "f.vdb");
  expectInputError([&] { readFloatGrid(dir / "f.vdb", "temperature"); }, {"f.vdb", "'temperature'", "density"});
  expectInputError([&] { readVectorGrid(dir / "f.vdb", "density"); }, {"f.vdb", "float"});
  expectInputError([&] { readPoints(dir / "f.vdb", "density"); }, {"f.vdb", "float"});
  expectInputError([&] { readFloatGrid(dir / "missing.vdb", "density"); }, {"missing.vdb"});
  writeText(dir / "junk.vdb", "definitely not a vdb file");
  expectInputError([&] { readFloatGrid(dir / "junk.vdb", "density"); }, {"junk.vdb"});
  std::string bytes = test::readBytes(dir / "f.vdb");
  bytes.resize(bytes.size() / 2);
  writeText(dir / "cut.vdb", bytes);
  expectInputError([&] { readFloatGrid(dir / "cut.vdb", "density"); }, {"cut.vdb"});
}

}  // namespace
}  // namespace msim::io
