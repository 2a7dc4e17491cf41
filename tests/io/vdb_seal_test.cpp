#include "msim/io/vdb_seal.hpp"

#include <gtest/gtest.h>
#include <openvdb/openvdb.h>

#include "msim/io/vdb.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::readBytes;
using test::scratchDir;
using test::writeText;

std::filesystem::path writeSmallFrame(const std::filesystem::path& dir) {
  Grid<float, 3> density(GridSpec<3>(Vec3::Zero(), 0.25, IVec3(9, 7, 5)), 0.0f);
  for (std::size_t i = 0; i < density.count(); i += 3) density[i] = 0.1f * float(i % 17);
  VdbWriter writer;
  writer.addFloatGrid("density", density);
  writer.write(dir / "frame.vdb");
  return dir / "frame.vdb";
}

TEST(VdbSeal, WrittenFilesCarryAMatchingChecksum) {
  const auto file = writeSmallFrame(scratchDir());
  std::string bytes = readBytes(file);
  EXPECT_EQ(checkVdbSeal(bytes, file), VdbSeal::Verified);
  EXPECT_EQ(bytes, readBytes(file)) << "checking must leave the bytes as they were";
  // The seal is ordinary file metadata that OpenVDB's own reader shows.
  openvdb::initialize();
  openvdb::io::File vdb(file.string());
  vdb.open();
  const std::string seal = vdb.getMetadata()->metaValue<std::string>(kVdbSealKey);
  EXPECT_EQ(seal.size(), 16u);
  EXPECT_NE(seal, kVdbSealPlaceholder);
  EXPECT_EQ(VdbFile(file, VdbProvenance::MsimRun).gridNames(), std::vector<std::string>{"density"});
}

TEST(VdbSeal, AnyChangedByteIsCaughtBeforeParsing) {
  const auto dir = scratchDir();
  const auto file = writeSmallFrame(dir);
  const std::string original = readBytes(file);
  // Every byte in turn (a stride keeps the test short): flipped, the file no longer matches.
  for (std::size_t at = 0; at < original.size(); at += 7) {
    std::string damaged = original;
    damaged[at] = static_cast<char>(damaged[at] ^ 0x5a);
    const auto path = dir / "damaged.vdb";
    writeText(path, damaged);
    try {
      VdbFile read(path, VdbProvenance::MsimRun);
      ADD_FAILURE() << "byte " << at << " changed and the file was still read";
    } catch (const InputError& e) {
      EXPECT_NE(std::string(e.what()).find("damaged.vdb"), std::string::npos) << e.what();
    }
  }
  std::string cut = original.substr(0, original.size() - 10);
  writeText(dir / "cut.vdb", cut);
  expectInputError([&] { VdbFile(dir / "cut.vdb", VdbProvenance::AnyTool); }, {"cut.vdb", "checksum"});
}

TEST(VdbSeal, FilesOfOtherToolsAreReadOnlyWhenAnyToolMayHaveWrittenThem) {
  const auto dir = scratchDir();
  openvdb::initialize();
  auto grid = openvdb::FloatGrid::create(0.0f);
  grid->setName("density");
  grid->tree().setValue(openvdb::Coord(1, 2, 3), 2.5f);
  openvdb::io::File(dir.string() + "/other.vdb").write(openvdb::GridPtrVec{grid});
  std::string bytes = readBytes(dir / "other.vdb");
  EXPECT_EQ(checkVdbSeal(bytes, dir / "other.vdb"), VdbSeal::Absent);
  const Grid<float, 3> read = VdbFile(dir / "other.vdb", VdbProvenance::AnyTool).floatGrid("density");
  EXPECT_EQ(read.count(), 1u);
  EXPECT_EQ(read[0], 2.5f);
  expectInputError([&] { VdbFile(dir / "other.vdb", VdbProvenance::MsimRun); }, {"other.vdb", "no msim checksum"});
}

}  // namespace
}  // namespace msim::io
