#include "msim/scene/runner.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <cstdio>
#include <regex>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/core/timer.hpp"
#include "msim/io/atomic_file.hpp"
#include "msim/io/csv.hpp"
#include "msim/io/png.hpp"
#include "msim/io/video.hpp"
#include "msim/parallel/mpi_session.hpp"
#include "msim/scene/interrupt.hpp"
#include "msim/scene/progress_bar.hpp"
#include "msim/scene/saved_frames.hpp"
#include "msim/version.hpp"

namespace msim::scene {

namespace fs = std::filesystem;
using nlohmann::json;

fs::path frameFile(const fs::path& dir, const std::string& name, int frame, const std::string& extension) {
  return dir / fmt::format("{}_{:04d}.{}", name, frame, extension);
}

namespace {

struct Layout {
  fs::path root, vdbDir, pngDir, renderDir;
  bool vdb = false, png = false, mp4 = false;
  io::VdbWriteOptions vdbOptions;
  RenderKeys render;  // render.enabled: each saved frame is also rendered into renderDir
  std::string name;
};

Layout layoutFor(const Scene& scene, const fs::path& outDir) {
  const json& o = scene.resolved.at("outputs");
  Layout l;
  l.root = outDir;
  l.vdbDir = outDir / "vdb";
  l.pngDir = outDir / "png";
  l.vdb = o.at("vdb").get<bool>();
  l.vdbOptions.halfFloat = o.at("vdb_half_float").get<bool>();
  l.vdbOptions.fogTolerance = o.at("vdb_fog_tolerance").get<float>();
  l.png = o.at("png").get<bool>();
  l.mp4 = o.at("mp4").get<bool>() && l.png;
  l.name = scene.name();
  l.renderDir = outDir / "render";
  l.render = renderKeys(scene.resolved.at("render"), scene.file.string(), scene.directory());
  if (scene.dimensions == 3) l.render.domain = scene.gridSpec<3>();
  if (l.render.enabled && scene.dimensions != 3)
    throw InputError(scene.file.string() + ": 'render.enabled' needs a 3D scene (2D scenes have their preview)");
  if (l.render.enabled && !l.vdb)
    throw InputError(scene.file.string() + ": 'render.enabled' renders the saved VDB frames; set 'outputs.vdb' to true");
  return l;
}

// What a run left in its folder and how to look at it, for the end of the run.
std::string describeOutputs(const Layout& l, int lastFrame) {
  std::string text = fmt::format("\nwrote {}:\n", l.root.string());
  const auto line = [&](const fs::path& path, const std::string& what) {
    if (fs::exists(path)) text += fmt::format("  {:<40} {}\n", path.string(), what);
  };
  line(l.root / (l.name + ".mp4"), "movie of the previews (any video player, e.g. ffplay)");
  line(l.root / (l.name + "_render.mp4"), "movie of the rendered frames");
  line(frameFile(l.renderDir, l.name, lastFrame, "png"), "physically based render of the last frame");
  line(frameFile(l.pngDir, l.name, lastFrame, "png"), "preview of the last frame (png/ holds every frame)");
  line(frameFile(l.vdbDir, l.name, lastFrame, "vdb"),
       "last frame's volumes (vdb/ holds every frame: Houdini, Blender, vdb_print; msim render)");
  line(l.root / "run.json", "parameters, statistics and timings of the run");
  return text;
}

bool frameComplete(const Layout& l, int frame) {
  if (l.vdb && !fs::exists(frameFile(l.vdbDir, l.name, frame, "vdb"))) return false;
  if (l.png && !fs::exists(frameFile(l.pngDir, l.name, frame, "png"))) return false;
  if (l.render.enabled && !fs::exists(frameFile(l.renderDir, l.name, frame, "png"))) return false;
  return l.vdb || l.png;
}

// Removes frame files of an earlier run with the same name so a fresh run never mixes with them.
void clearFrames(const Layout& l) {
  const std::regex pattern(fmt::format("{}_[0-9]{{4,}}\\.(vdb|png)", l.name));
  for (const fs::path& dir : {l.vdbDir, l.pngDir, l.renderDir}) {
    if (!fs::exists(dir)) continue;
    for (const auto& entry : fs::directory_iterator(dir))
      if (std::regex_match(entry.path().filename().string(), pattern)) fs::remove(entry.path());
  }
}

void writeJson(const fs::path& path, const json& document) {
  io::writeFileAtomically(path, [&](const fs::path& tmp) {
    std::FILE* f = std::fopen(tmp.c_str(), "w");
    if (!f) throw std::runtime_error("cannot write " + tmp.string());
    const std::string text = document.dump(2) + "\n";
    const bool ok = std::fwrite(text.data(), 1, text.size(), f) == text.size();
    if (std::fclose(f) != 0 || !ok) throw std::runtime_error("cannot write " + tmp.string());
  });
}

void writeStatsCsv(const fs::path& path, const json& frames) {
  if (frames.empty()) return;
  std::vector<std::string> columns;
  for (const auto& [key, value] : frames.front().items()) columns.push_back(key);
  io::CsvWriter csv(path, columns);
  std::vector<double> row(columns.size());
  for (const json& f : frames) {
    for (std::size_t c = 0; c < columns.size(); ++c) row[c] = f.at(columns[c]).get<double>();
    csv.addRow(row);
  }
  csv.commit();
}

json timingJson(const StageTimers& timers) {
  json stages = json::array();
  for (const auto& s : timers.table())
    stages.push_back({{"stage", s.name}, {"seconds", s.seconds}, {"calls", s.calls}, {"percent", s.percent}});
  return stages;
}

// The frame's files: per-frame data, the VDB, its render, the preview.
void writeFrameFiles(const Layout& layout, const Phenomenon& phenomenon, StageTimers& timers, int frame,
                     double frameEnd, int lastFrame) {
  {
    ScopedStage stage(timers, "write frame data");
    phenomenon.writeFrameData(layout.root, frame);
  }
  if (layout.vdb) {
    ScopedStage stage(timers, "write vdb");
    io::VdbWriter writer(layout.vdbOptions);
    phenomenon.writeVolume(writer);
    const io::VdbFrameInfo info{layout.name, frame, frameEnd};
    writer.write(frameFile(layout.vdbDir, layout.name, frame, "vdb"), &info);
  }
  if (layout.render.enabled && (!layout.render.lastFrameOnly || frame == lastFrame)) {
    // From the file just written, exactly as 'msim render' would make it later.
    ScopedStage stage(timers, "render frame");
    renderSavedFrame(io::VdbFile(frameFile(layout.vdbDir, layout.name, frame, "vdb"), io::VdbProvenance::MsimRun),
                     layout.render, frameFile(layout.renderDir, layout.name, frame, "png"));
  }
  if (layout.png) {
    ScopedStage stage(timers, "write png");
    io::writePng(frameFile(layout.pngDir, layout.name, frame, "png"), phenomenon.preview());
  }
}

class RunRecord {
 public:
  RunRecord(const Scene& scene, const RunOptions& options, const Layout& layout)
      : path_(layout.root / "run.json"), statsPath_(layout.root / "stats.csv") {
    doc_ = {{"msim_version", kVersion},
            {"scene_file", scene.file.string()},
            {"command_line", options.commandLine},
            {"status", "running"},
            {"grid",
             {{"dimensions", scene.dimensions},
              {"resolution", std::vector<int>(scene.resolution.data(), scene.resolution.data() + scene.dimensions)},
              {"dx_m", scene.dx},
              {"cells", scene.cellCount()},
              {"memory_estimate_bytes", scene.memoryEstimate}}},
            {"frames_planned", scene.frameCount},
            {"fps", scene.fps},
            {"parameters", scene.resolved},
            {"frames", json::array()}};
  }
  // Frame statistics of the run being resumed, if its run.json is readable.
  void adoptPreviousFrames(int upToFrame) {
    std::FILE* f = std::fopen(path_.c_str(), "r");
    if (!f) return;
    const json previous = json::parse(f, nullptr, false);
    std::fclose(f);
    if (previous.is_discarded() || !previous.contains("frames")) return;
    for (const json& frame : previous.at("frames"))
      if (frame.value("frame", 0.0) <= upToFrame) doc_["frames"].push_back(frame);
  }
  void addFrame(json stats) { doc_["frames"].push_back(std::move(stats)); }
  void save(const std::string& status, const StageTimers& timers, double wallSeconds) {
    doc_["status"] = status;
    doc_["wall_seconds"] = wallSeconds;
    doc_["timings"] = timingJson(timers);
    if (!doc_["frames"].empty()) doc_["summary"] = doc_["frames"].back();
    writeJson(path_, doc_);
    writeStatsCsv(statsPath_, doc_["frames"]);
  }
  void note(const std::string& key, const std::string& value) { doc_[key] = value; }
  void results(nlohmann::json value) { doc_["results"] = std::move(value); }
  const json& frames() const { return doc_["frames"]; }

 private:
  fs::path path_, statsPath_;
  json doc_;
};

}  // namespace

RunStatus runScene(const Scene& scene, const RunOptions& options) {
  const auto wallStart = std::chrono::steady_clock::now();
  auto wall = [&] { return std::chrono::duration<double>(std::chrono::steady_clock::now() - wallStart).count(); };
  const Layout layout = layoutFor(scene, options.outDir);
  const int lastFrame = options.frameLimit > 0 ? std::min(options.frameLimit, scene.frameCount) : scene.frameCount;
  if (options.resume && !layout.vdb)
    throw InputError(scene.file.string() + ": --resume needs the VDB frames, but 'outputs.vdb' is false");
  // Under mpirun every rank runs this loop; rank 0 alone writes files and reports.
  const int ranks = parallel::worldSize();
  const bool writesFiles = parallel::worldRank() == 0;
  if (ranks > 1 && !scene.type->splitsAmongProcesses)
    throw InputError(fmt::format("{}: 'phenomenon' {} runs on one process; run it without mpirun (-np {})",
                                 scene.file.string(), scene.type->name, ranks));

  // Build first: a scene that fails here (a mesh that does not load, a source outside the
  // domain) must not leave even an empty output folder behind.
  StageTimers timers;
  std::unique_ptr<Phenomenon> phenomenon;
  {
    ScopedStage stage(timers, "setup");
    // Under mpirun each rank builds its block, and an error may strike some ranks only.
    phenomenon = parallel::collectively([&] { return scene.type->create(scene, timers); });
  }
  if (writesFiles) {
    fs::create_directories(layout.root);
    if (layout.vdb) fs::create_directories(layout.vdbDir);
    if (layout.png) fs::create_directories(layout.pngDir);
    if (layout.render.enabled) fs::create_directories(layout.renderDir);
    for (const fs::path& dir : {layout.root, layout.vdbDir, layout.pngDir, layout.renderDir})
      io::removeStaleTemporaries(dir);
  }
  RunRecord record(scene, options, layout);
  if (ranks > 1) record.note("mpi_processes", std::to_string(ranks));

  int firstFrame = 1;
  long resumedSteps = 0;
  if (options.resume) {
    int done = 0;
    while (done < lastFrame && frameComplete(layout, done + 1)) ++done;
    if (done > 0) {
      ScopedStage stage(timers, "resume: read frame");
      // The steps taken so far: the substeps of the frames the run's record holds (rank 0 keeps
      // the record and reads it; every rank takes its count).
      if (writesFiles) {
        record.adoptPreviousFrames(done);
        for (const json& f : record.frames()) resumedSteps += f.value("substeps", 0L);
      }
      resumedSteps = parallel::fromRankZero(resumedSteps);
      if (writesFiles && record.frames().size() != static_cast<std::size_t>(done))
        logger().warn("{}: run.json does not hold the {} frames written: the step count goes on from {}, the steps of "
                      "those it holds (what happens every so many steps, such as a liquid's reseeding, shifts)",
                      layout.root.string(), done, resumedSteps);
      phenomenon->restore(frameFile(layout.vdbDir, layout.name, done, "vdb"), done / scene.fps, resumedSteps);
      if (layout.vdbOptions.halfFloat || layout.vdbOptions.fogTolerance > 0.0f)
        logger().info("frame {} was stored with outputs.vdb_fog_tolerance = {:g}{}: the resumed run continues from "
                      "those values, close to but not bit-equal with an uninterrupted run (a tolerance of 0 and full "
                      "floats make resuming exact)",
                      done, layout.vdbOptions.fogTolerance, layout.vdbOptions.halfFloat ? " in half floats" : "");
    }
    firstFrame = done + 1;
    logger().info("resuming after frame {} of {}", done, lastFrame);
  } else if (writesFiles) {
    clearFrames(layout);
  }

  const double frameDt = 1.0 / scene.fps;
  const int maxSubsteps = scene.resolved.at("time").at("max_substeps").get<int>();
  long stepIndex = resumedSteps;
  ProgressBar progress(firstFrame, lastFrame);
  RunStatus status = RunStatus::Complete;
  try {
    for (int frame = firstFrame; frame <= lastFrame; ++frame) {
      const double frameEnd = frame * frameDt;
      double time = (frame - 1) * frameDt, remaining = frameDt;
      int substeps = 0;
      while (remaining > 1e-12 * frameDt) {
        const double stable = phenomenon->stableTimestep();
        // A fluid at rest has no CFL limit (stable = inf): the rest of the frame is one step.
        const double needed = std::max(1.0, std::ceil(remaining / stable));
        if (!(stable > 0.0) || substeps + needed > maxSubsteps)
          throw SimulationError(fmt::format(
              "step {} (t = {:.4g} s): frame {} needs more than time.max_substeps = {} substeps (stable step {:.3g} s "
              "for a frame of {:.3g} s): the flow is too fast for the grid (CFL)",
              stepIndex, time, frame, maxSubsteps, stable, frameDt));
        const double dt = remaining / needed;
        phenomenon->step(dt);
        ++stepIndex;
        ++substeps;
        remaining -= dt;
        time = frameEnd - remaining;
      }
      {
        ScopedStage stage(timers, "check finite");
        phenomenon->checkFinite(stepIndex, frameEnd);
      }
      phenomenon->endFrame();
      if (writesFiles) {
        writeFrameFiles(layout, *phenomenon, timers, frame, frameEnd, lastFrame);
        json stats = {{"frame", frame}, {"time_s", frameEnd}, {"substeps", substeps}};
        stats.update(phenomenon->statistics());
        record.addFrame(std::move(stats));
        record.save(frame == lastFrame ? "complete" : "running", timers, wall());
        if (options.showProgress) progress.update(frame, substeps);
      }
      if (parallel::anyRank(interruptRequested()) && frame < lastFrame) {
        status = RunStatus::Interrupted;
        break;
      }
    }
  } catch (const std::exception& e) {
    if (options.showProgress) progress.finish();
    if (writesFiles) {
      record.note("error", e.what());
      record.save("failed", timers, wall());
    }
    throw;
  }
  if (options.showProgress) progress.finish();
  if (!writesFiles) return status;

  if (status == RunStatus::Complete) {
    ScopedStage stage(timers, "finish run");
    record.results(phenomenon->finishRun(layout.root, record.frames()));
  }
  if (status == RunStatus::Complete && layout.mp4) {
    ScopedStage stage(timers, "encode mp4");
    std::vector<fs::path> frames;
    for (int f = 1; f <= lastFrame; ++f) frames.push_back(frameFile(layout.pngDir, layout.name, f, "png"));
    const io::VideoResult video = io::encodeMp4(frames, scene.fps, layout.root / (layout.name + ".mp4"));
    if (!video.written) {
      logger().warn("{}", video.note);
      record.note("mp4", video.note);
    }
    if (layout.render.enabled && !layout.render.lastFrameOnly && video.written) {
      std::vector<fs::path> rendered;
      for (int f = 1; f <= lastFrame; ++f) rendered.push_back(frameFile(layout.renderDir, layout.name, f, "png"));
      io::encodeMp4(rendered, scene.fps, layout.root / (layout.name + "_render.mp4"));
    }
  }
  record.save(status == RunStatus::Complete ? "complete" : "interrupted", timers, wall());
  if (options.showProgress) {
    std::fprintf(stderr, "%s", timers.formatTable().c_str());
    std::fprintf(stderr, "%s", describeOutputs(layout, lastFrame).c_str());
  }
  return status;
}

}  // namespace msim::scene
