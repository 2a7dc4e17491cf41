// Frame I/O: a 128^3 smoke-like density written to and read back from a sealed .vdb (the
// checksum that lets msim check a frame before OpenVDB parses it is part of both), and the seal
// check alone over the same file's bytes.
#include <benchmark/benchmark.h>

#include <cmath>
#include <filesystem>
#include <fstream>

#include "msim/io/vdb.hpp"
#include "msim/io/vdb_seal.hpp"

using namespace msim;

namespace {

constexpr int kRes = 128;

// A ball of smoke filling about a third of the box: the rest stays inactive in the VDB tree.
const Grid<float, 3>& density() {
  static const Grid<float, 3> g = [] {
    Grid<float, 3> out(GridSpec<3>(Vec3::Zero(), 1.0 / kRes, IVec3::Constant(kRes)), 0.0f);
    for (std::size_t i = 0; i < out.count(); ++i) {
      const Vec3 x = out.spec().cellCenter(out.coord(i)) - Vec3::Constant(0.5);
      const double r = x.norm();
      if (r < 0.42) out[i] = float(0.5 + 0.5 * std::sin(40.0 * x.x()) * std::cos(30.0 * x.y()));
    }
    return out;
  }();
  return g;
}

std::filesystem::path frameFile() {
  return std::filesystem::temp_directory_path() / "msim_io_bench.vdb";
}

void BM_VdbWriteSealed(benchmark::State& state) {
  for (auto _ : state) {
    io::VdbWriter writer;
    writer.addFloatGrid("density", density());
    writer.write(frameFile());
  }
  state.counters["MB"] = double(std::filesystem::file_size(frameFile())) * 1e-6;
}
BENCHMARK(BM_VdbWriteSealed)->Unit(benchmark::kMillisecond);

void BM_VdbReadChecked(benchmark::State& state) {
  io::VdbWriter writer;
  writer.addFloatGrid("density", density());
  writer.write(frameFile());
  for (auto _ : state) {
    const io::VdbFile frame(frameFile(), io::VdbProvenance::MsimRun);
    benchmark::DoNotOptimize(frame.floatGrid("density"));
  }
}
BENCHMARK(BM_VdbReadChecked)->Unit(benchmark::kMillisecond);

void BM_VdbSealCheck(benchmark::State& state) {
  io::VdbWriter writer;
  writer.addFloatGrid("density", density());
  writer.write(frameFile());
  std::ifstream in(frameFile(), std::ios::binary);
  std::string bytes((std::istreambuf_iterator<char>(in)), std::istreambuf_iterator<char>());
  for (auto _ : state) benchmark::DoNotOptimize(io::checkVdbSeal(bytes, frameFile()));
  state.SetBytesProcessed(state.iterations() * static_cast<std::int64_t>(bytes.size()));
}
BENCHMARK(BM_VdbSealCheck)->Unit(benchmark::kMillisecond);

}  // namespace
