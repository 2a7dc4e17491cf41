// Fuzzing the VDB reader as msim reads its own frames back (msim render of a run, --resume):
// mutations of small sealed frames with float, vector and point grids. Every case reads or is
// refused with an InputError before OpenVDB parses damaged data.
#include <gtest/gtest.h>

#include "fuzz_case.hpp"
#include "msim/io/vdb.hpp"
#include "mutator.hpp"

namespace msim::fuzz {
namespace {

std::string smallFrame(const std::filesystem::path& dir) {
  const GridSpec<3> spec(Vec3(-0.5, 0.0, 0.25), 0.125, IVec3(11, 9, 6));
  Grid<float, 3> density(spec, 0.0f);
  Grid<Vecf<3>, 3> velocity(spec, Vecf<3>::Zero());
  for (std::size_t i = 0; i < density.count(); ++i) {
    if (i % 4 == 0) continue;
    density[i] = 0.01f * float(i % 97);
    velocity[i] = Vecf<3>(0.1f * float(i % 5), -0.2f, 0.03f * float(i % 11));
  }
  io::PointCloud agents;
  io::PointAttribute radius{"radius", {}};
  for (int i = 0; i < 40; ++i) {
    agents.positions.push_back(Vecf<3>(0.1f * float(i % 7), 0.2f * float(i / 7), 0.0f));
    radius.values.push_back(0.2f + 0.01f * float(i));
  }
  agents.attributes.push_back(radius);
  io::VdbWriter writer;
  writer.addFloatGrid("density", density);
  writer.addVectorGrid("vel", velocity);
  writer.addPoints("agents", agents, 0.5);
  writer.write(dir / "frame.vdb");
  return readBytes(dir / "frame.vdb");
}

// Reads everything a frame holds, as render and resume would.
void readWholeFrame(const std::filesystem::path& file) {
  const io::VdbFile frame(file, io::VdbProvenance::MsimRun);
  for (const auto& name : frame.gridNames()) {
    if (name == "density") frame.floatGrid(name);
    if (name == "vel") frame.vectorGrid(name);
    if (name == "agents") frame.points(name);
  }
}

TEST(VdbReaderFuzz, MutatedFramesReadOrFailWithInputError) {
  const auto dir = fuzzScratch("vdb");
  const std::string original = smallFrame(dir);
  readWholeFrame(dir / "frame.vdb");
  Mutator mutator(16);
  Outcomes outcomes;
  constexpr int kCases = 1200;
  for (int k = 0; k < kCases; ++k) {
    const std::string name = "vdb_" + std::to_string(k);
    const auto input = dir / (name + ".vdb");
    writeBytes(input, mutator.mutateBytes(original));
    runCase(name, input, [&] { readWholeFrame(input); }, outcomes);
  }
  std::printf("vdb: %d cases, %d read, %d refused with InputError\n", kCases, outcomes.accepted, outcomes.rejected);
  EXPECT_GT(outcomes.rejected, kCases / 2);
}

}  // namespace
}  // namespace msim::fuzz
