#pragma once
// The contract between the time loop (runner) and a phenomenon. A phenomenon owns its state and
// parameters; the runner owns time, substeps, frames, files and the user's interrupts.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/core/timer.hpp"
#include "msim/io/png.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

struct Scene;

class Phenomenon {
 public:
  virtual ~Phenomenon() = default;
  // Largest stable step from the current state, already scaled by the scene's CFL factor [s].
  virtual double stableTimestep() const = 0;
  virtual void step(double dt) = 0;
  // Throws SimulationError naming the field and `stepIndex` if the state is not finite.
  virtual void checkFinite(long stepIndex, double time) const = 0;
  // Called once after the last substep of every frame, before its outputs (per-frame
  // measurements that the outputs and statistics() then report). Nothing by default.
  virtual void endFrame() {}
  // Frame outputs. writeVolume adds the frame's grids and points to the runner's writer (the
  // runner owns the file: its name, storage options and metadata).
  virtual void writeVolume(io::VdbWriter& writer) const = 0;
  virtual io::Image preview() const = 0;
  // Restores the state saved by writeVolume at simulated time `time` [s] after `steps` steps (for
  // --resume; the step count serves what happens every so many steps).
  virtual void restore(const std::filesystem::path& vdbFile, double time, long steps) = 0;
  // Summary numbers of the current state, one JSON object of named numbers.
  virtual nlohmann::json statistics() const = 0;
  // In a run split among MPI processes (PhenomenonType::splitsAmongProcesses) every rank calls
  // stableTimestep, step, checkFinite and endFrame together (collective: endFrame gathers the
  // frame on rank 0); the outputs below (writeVolume, preview, statistics, writeFrameData,
  // finishRun) are called on rank 0 only.
  // Per-frame files besides the VDB and the preview (a crowd's trajectory rows), written before
  // the VDB so that a frame whose VDB exists has them too (--resume). None by default.
  virtual void writeFrameData(const std::filesystem::path& /*runDir*/, int /*frame*/) const {}
  // The run is complete: summary files (plots, joined tables) in runDir from the statistics of
  // every frame (run.json's "frames"). Returns named results stored in run.json as "results".
  virtual nlohmann::json finishRun(const std::filesystem::path& /*runDir*/, const nlohmann::json& /*frames*/) {
    return nlohmann::json::object();
  }
};

// A kind of phenomenon the scene key "phenomenon" can name.
struct PhenomenonType {
  std::string name;
  std::string description;
  // Adds the phenomenon's own keys to the root scene schema.
  void (*declare)(Schema& root);
  // Bytes of memory per grid cell while running (state, scratch, output buffers).
  double (*bytesPerCell)(int dimensions, const nlohmann::json& resolved);
  std::unique_ptr<Phenomenon> (*create)(const Scene& scene, StageTimers& timers);
  // Whether `mpirun -np N msim run` splits it among the N processes (msim/parallel).
  bool splitsAmongProcesses = false;
};

const std::vector<PhenomenonType>& phenomenonTypes();
const PhenomenonType* findPhenomenonType(const std::string& name);

}  // namespace msim::scene
