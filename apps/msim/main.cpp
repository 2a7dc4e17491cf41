// msim: the command-line program. run / info / validate a scene; render saved frames.
// Exit codes: 0 success, 2 bad input (scene, command line, files), 3 simulation failure,
// 130 interrupted by the user (the last frame written is complete; --resume continues).
#include <algorithm>
#include <cstdio>
#include <memory>
#include <optional>
#include <string>
#include <vector>

#include <CLI/CLI.hpp>
#include <fmt/format.h>
#include <tbb/global_control.h>
#include <tbb/info.h>

#include "msim/core/error.hpp"
#include "msim/core/float_environment.hpp"
#include "msim/core/log.hpp"
#include "msim/core/system_memory.hpp"
#include "msim/io/png.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/render/image_detail.hpp"
#include "msim/scene/interrupt.hpp"
#include "msim/scene/runner.hpp"
#include "msim/scene/saved_frames.hpp"
#include "msim/scene/scene_file.hpp"
#include "msim/scene/schema/describe.hpp"
#include "msim/scene/reports/velocity_spectrum.hpp"
#include "msim/version.hpp"

namespace {

using namespace msim;

std::string joinArgs(int argc, char** argv) {
  std::string s;
  for (int i = 0; i < argc; ++i) s += (i ? " " : "") + std::string(argv[i]);
  return s;
}

void printInfo(const scene::Scene& s) {
  std::printf("scene        %s\n", s.file.c_str());
  std::printf("phenomenon   %s: %s\n", s.type->name.c_str(), s.type->description.c_str());
  std::printf("grid         %dD, %d x %d%s cells (%zu), dx = %.4g m\n", s.dimensions, s.resolution.x(),
              s.resolution.y(), s.dimensions == 3 ? fmt::format(" x {}", s.resolution.z()).c_str() : "", s.cellCount(),
              s.dx);
  std::printf("frames       %d at %.4g fps (%.4g s)\n", s.frameCount, s.fps, s.frameCount / s.fps);
  std::printf("memory       about %s (available: %s)\n\n", formatBytes(s.memoryEstimate).c_str(),
              formatBytes(static_cast<double>(availableMemoryBytes())).c_str());
  const auto rows = scene::describe(scene::sceneSchema(*s.type), s.resolved);
  std::printf("%s", scene::formatParamTable(rows).c_str());
}

}  // namespace

int main(int argc, char** argv) {
  flushSubnormalsToZero();
  // Started by mpirun: MPI runs for the whole program, and `msim run` splits the scene among the
  // processes (msim/parallel). Otherwise MPI is never initialised.
  std::optional<parallel::MpiSession> mpi;
  if (parallel::launchedByMpi()) mpi.emplace(argc, argv);
  const int rank = parallel::worldRank(), ranks = parallel::worldSize();
  CLI::App app{"msim: multi-scale simulation of natural phenomena"};
  app.set_version_flag("--version", std::string("msim ") + kVersion);
  app.require_subcommand(1);
  app.fallthrough();  // --threads and -q may follow the subcommand
  int threads = 0;
  bool quiet = false;
  app.add_option("--threads", threads, "worker threads (default: all cores)")->check(CLI::NonNegativeNumber);
  app.add_flag("-q,--quiet", quiet, "only errors, no progress bar");

  std::string scenePath;
  std::vector<std::string> overrides;
  scene::RunOptions runOptions;
  int frames = -1;
  auto* run = app.add_subcommand("run", "simulate a scene and write its frames");
  run->add_option("scene", scenePath, "scene file (.json)")->required();
  run->add_option("--out", runOptions.outDir, "output folder (default: out/<scene name>)");
  run->add_option("--frames", frames, "stop after N frames")->check(CLI::PositiveNumber);
  run->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");
  run->add_flag("--resume", runOptions.resume, "continue after the last complete frame in --out");

  auto* info = app.add_subcommand("info", "list every resolved parameter with default, unit and memory estimate");
  info->add_option("scene", scenePath, "scene file (.json)")->required();
  info->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");

  auto* validate = app.add_subcommand("validate", "check a scene file without running it");
  validate->add_option("scene", scenePath, "scene file (.json)")->required();
  validate->add_option("--set", overrides, "override a scene key: key.path=value (repeatable)");

  std::string renderInput, renderOutput;
  auto* render = app.add_subcommand("render", "render saved frames (a run folder or one .vdb file) without simulating");
  render->add_option("input", renderInput, "a folder written by 'msim run', or a .vdb file")->required();
  render->add_option("--out", renderOutput, "output folder (run; default <run>/render) or file (.vdb; default <file>.png)");
  render->add_option("--set", overrides, "override a render key: render.key.path=value (repeatable)");
  bool renderLast = false;
  render->add_flag("--last", renderLast, "a run folder: render only its last frame");

  scene::SpectrumJob spectrumJob;
  auto* spectrum = app.add_subcommand("spectrum", "kinetic energy spectrum of saved 3D velocity fields (.vdb), as CSV and PNG");
  spectrum->add_option("inputs", spectrumJob.inputs, "one or more .vdb files, compared in one chart")->required();
  spectrum->add_option("--grid", spectrumJob.grid, "the vector grid (default vel)");
  spectrum->add_option("--out", spectrumJob.output, "prefix of the CSV files and the chart (default <first file>_spectrum)");

  std::vector<std::string> detailPictures;
  std::vector<int> detailCrop;
  auto* detail = app.add_subcommand(
      "detail", "share of a picture's spectral energy above half the Nyquist frequency (fine detail, 0..1)");
  detail->add_option("pictures", detailPictures, "one or more .png pictures")->required();
  detail->add_option("--crop", detailCrop, "measure only the pixels X0 <= x < X1, Y0 <= y < Y1 (y from the top)")
      ->expected(4)
      ->allow_extra_args(false);

  std::string phenomenonName;
  auto* schema = app.add_subcommand("schema", "print the Markdown reference of every scene key of a phenomenon");
  schema->add_option("phenomenon", phenomenonName, "phenomenon name, e.g. gas")->required();

  try {
    app.parse(argc, argv);
  } catch (const CLI::ParseError& e) {
    const int code = app.exit(e);
    return code == 0 ? 0 : kExitInputError;
  }

  initLogging(spdlog::level::info);
  setQuiet(quiet || rank > 0);  // rank 0 speaks for a split run
  // Processes sharing a machine share its cores: by default each takes its part of them.
  if (threads == 0 && ranks > 1)
    threads = std::max(1, static_cast<int>(tbb::info::default_concurrency()) / parallel::ranksOnThisNode());
  std::optional<tbb::global_control> threadLimit;
  if (threads > 0) threadLimit.emplace(tbb::global_control::max_allowed_parallelism, threads);

  try {
    if (ranks > 1 && !*run)
      throw InputError(fmt::format("only 'msim run' splits work among MPI processes; run this command without mpirun "
                                   "(-np {})", ranks));
    if (*schema) {
      const scene::PhenomenonType* type = scene::findPhenomenonType(phenomenonName);
      if (!type) throw InputError(fmt::format("unknown phenomenon '{}'", phenomenonName));
      std::printf("%s", scene::markdownReference(scene::sceneSchema(*type)).c_str());
      return 0;
    }
    if (*spectrum) {
      const auto result = scene::velocitySpectrum(spectrumJob);
      for (const auto& r : result.at("spectra")) {
        const std::string fit = r.at("exponent").is_null()
                                    ? "no fit (too few shells)"
                                    : fmt::format("E ~ k^{:.3f} over {} shells", r.at("exponent").get<double>(),
                                                  r.at("shells_fitted").get<int>());
        fmt::print("{}: cube of {} voxels, {} -> {}\n", r.at("file").get<std::string>(), r.at("cube_voxels").get<int>(),
                   fit, r.at("csv").get<std::string>());
      }
      fmt::print("chart: {}\n", result.at("png").get<std::string>());
      return 0;
    }
    if (*detail) {
      for (const std::string& file : detailPictures) {
        const io::Image picture = io::readPng(file);
        render::PixelBox box{0, 0, picture.width, picture.height};
        if (!detailCrop.empty()) box = {detailCrop[0], detailCrop[1], detailCrop[2], detailCrop[3]};
        try {
          fmt::print("{:.3e}  {}\n", render::fineDetailShare(picture, box), file);
        } catch (const std::invalid_argument& e) {
          throw InputError(file + ": --crop: " + e.what());
        }
      }
      return 0;
    }
    if (*render) {
      scene::RenderJob job;
      job.input = renderInput;
      job.output = renderOutput;
      job.lastFrameOnly = renderLast;
      job.overrides = overrides;
      job.showProgress = !quiet;
      const auto written = scene::renderSavedFrames(job);
      logger().info("rendered {} frame{} -> {}", written.size(), written.size() == 1 ? "" : "s",
                    written.size() == 1 ? written.front().string() : written.front().parent_path().string());
      return 0;
    }
    const scene::Scene s = scene::loadScene(scenePath, overrides);
    if (*info) {
      printInfo(s);
      return 0;
    }
    if (*validate) {
      // Building the phenomenon also loads meshes and places sources: everything but stepping.
      StageTimers timers;
      s.type->create(s, timers);
      std::printf("%s: ok (%s, %zu cells, %d frames)\n", scenePath.c_str(), s.type->name.c_str(), s.cellCount(),
                  s.frameCount);
      return 0;
    }
    if (runOptions.outDir.empty()) runOptions.outDir = std::filesystem::path("out") / s.name();
    runOptions.frameLimit = frames;
    runOptions.showProgress = !quiet && rank == 0;
    runOptions.commandLine = joinArgs(argc, argv);
    scene::installInterruptHandler();
    logger().info("{}: {} {}D, {} x {}{} cells, {} frames -> {}", scenePath, s.type->name, s.dimensions,
                  s.resolution.x(), s.resolution.y(), s.dimensions == 3 ? fmt::format(" x {}", s.resolution.z()) : "",
                  s.frameCount, runOptions.outDir.string());
    const scene::RunStatus status = scene::runScene(s, runOptions);
    if (status == scene::RunStatus::Interrupted) {
      const int ranks = parallel::worldSize();
      logger().warn("interrupted; the frames written are complete. Continue with: {}msim run {} --out {} --resume",
                    ranks > 1 ? fmt::format("mpirun -np {} ", ranks) : "", scenePath, runOptions.outDir.string());
      return kExitInterrupted;
    }
    logger().info("done: {}", runOptions.outDir.string());
    return 0;
  } catch (const InputError& e) {
    // Bad input is found alike on every rank (the scene is read and checked by all): rank 0
    // reports it and every rank leaves with code 2.
    if (rank == 0) std::fprintf(stderr, "msim: error: %s\n", e.what());
    return kExitInputError;
  } catch (const SimulationError& e) {
    // A split run's checks (CFL, finite fields) are reduced over the ranks: all throw together.
    if (rank == 0) std::fprintf(stderr, "msim: simulation failed: %s\n", e.what());
    return kExitSimulationError;
  } catch (const std::exception& e) {
    // Anything else may have hit one rank only: stop them all rather than leave them waiting.
    if (ranks > 1) parallel::abortAll(MPI_COMM_WORLD, 1, std::string("error: ") + e.what());
    std::fprintf(stderr, "msim: error: %s\n", e.what());
    return 1;
  }
}
