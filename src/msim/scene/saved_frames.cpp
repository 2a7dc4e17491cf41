#include "msim/scene/saved_frames.hpp"

#include <algorithm>
#include <fstream>
#include <optional>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/log.hpp"
#include "msim/core/resample.hpp"
#include "msim/io/atomic_file.hpp"
#include "msim/io/exr.hpp"
#include "msim/io/obj.hpp"
#include "msim/io/ply.hpp"
#include "msim/io/vdb.hpp"
#include "msim/io/video.hpp"
#include "msim/scene/progress_bar.hpp"
#include "msim/scene/schema/json_file.hpp"
#include "msim/scene/schema/override.hpp"
#include "msim/scene/schema/resolve.hpp"

namespace msim::scene {

namespace fs = std::filesystem;

namespace {

// The smoke solver's obstacles, a signed distance at the cell centres (negative inside), drawn as
// opaque surfaces when a frame has them.

bool hasGrid(const std::vector<std::string>& grids, const std::string& name) {
  return !name.empty() && std::find(grids.begin(), grids.end(), name) != grids.end();
}

// A grid of a saved frame; a 2D scene's frame (one cell thick in z) becomes a slab `slabCells`
// thick, every layer a copy of the slice, so the 3D renderer sees the flow face-on with some body
// (obstacles become prisms, as a 2D obstacle is).
Grid<float, 3> readForRender(const io::VdbFile& frame, const std::string& name, int slabCells) {
  Grid<float, 3> grid = frame.floatGrid(name);
  if (grid.size().z() != 1 || slabCells <= 1) return grid;
  GridSpec<3> spec = grid.spec();
  spec.res.z() = slabCells;
  Grid<float, 3> slab(spec);
  const std::size_t layer = grid.count();
  for (int z = 0; z < slabCells; ++z)
    std::copy(grid.data().begin(), grid.data().end(), slab.data().begin() + static_cast<std::ptrdiff_t>(z * layer));
  return slab;
}

// The render.* keys of a run (or the defaults), with the job's overrides applied.
RenderKeys jobKeys(const nlohmann::json& storedRender, const std::vector<std::string>& overrides,
                   const std::string& source, const fs::path& baseDirectory) {
  nlohmann::json doc = {{"render", storedRender}};
  for (const auto& o : overrides) {
    if (o.rfind("render.", 0) != 0)
      throw InputError(fmt::format("--set {}: only render.* keys can change when rendering saved frames", o));
    applyOverride(doc, o);
  }
  // Resolved as the scene's own "render" key, so errors name 'render.camera.fov', not 'camera.fov'.
  Schema root = Schema::object("the render keys of saved frames");
  root.field("render", renderSchema());
  return renderKeys(resolve(root, doc, source).at("render"), source, baseDirectory);
}

// The grid of a 3D run from its run.json (domain.min, the cell size and resolution), if it says.
std::optional<GridSpec<3>> runDomain(const nlohmann::json& run) {
  const nlohmann::json grid = run.value("grid", nlohmann::json::object());
  const nlohmann::json domain = run.value("parameters", nlohmann::json::object()).value("domain", nlohmann::json::object());
  if (grid.value("dimensions", 0) != 3 || !grid.contains("resolution") || !grid.contains("dx_m") || !domain.contains("min"))
    return std::nullopt;
  GridSpec<3> spec;
  spec.dx = grid.at("dx_m").get<double>();
  for (int a = 0; a < 3; ++a) {
    spec.origin[a] = domain.at("min").at(a).get<double>();
    spec.res[a] = grid.at("resolution").at(a).get<int>();
  }
  return spec;
}

// The surface mesh a cloth or solid run wrote beside a frame: <run>/mesh/<stem>.ply (or .obj) for
// <run>/vdb/<stem>.vdb.
std::optional<TriangleMesh> frameMesh(const fs::path& vdbFile) {
  const fs::path dir = vdbFile.parent_path().parent_path() / "mesh";
  const std::string stem = vdbFile.stem().string();
  if (fs::exists(dir / (stem + ".ply"))) return io::readPlyMesh(dir / (stem + ".ply")).mesh;
  if (fs::exists(dir / (stem + ".obj"))) return io::readObj(dir / (stem + ".obj"));
  return std::nullopt;
}

}  // namespace

void renderSavedFrame(const io::VdbFile& frame, const RenderKeys& keys, const fs::path& png,
                      render::FrameTimings* timings) {
  const std::vector<std::string> grids = frame.gridNames();
  const std::string vdbFile = frame.path().string();
  std::optional<Grid<float, 3>> liquid;
  if (hasGrid(grids, keys.liquidGrid)) liquid = readForRender(frame, keys.liquidGrid, keys.slabCells);
  // A cloth or solid run: its surface mesh in the run's grid.
  std::optional<TriangleMesh> surface;
  if (!hasGrid(grids, keys.densityGrid) && !liquid && keys.domain) surface = frameMesh(frame.path());
  if (!hasGrid(grids, keys.densityGrid) && !liquid && !surface)
    throw InputError(fmt::format("{}: no grid '{}' or '{}' to render (the file has: {}) and no surface mesh in the "
                                 "run's mesh/ folder; set render.grids.density or render.grids.liquid",
                                 vdbFile, keys.densityGrid, keys.liquidGrid, fmt::join(grids, ", ")));
  // A liquid run has no smoke: an empty medium of the liquid's layout; a cloth's, of the run's grid.
  const Grid<float, 3> density = hasGrid(grids, keys.densityGrid) ? readForRender(frame, keys.densityGrid, keys.slabCells)
                                 : liquid ? Grid<float, 3>(liquid->spec(), liquid->size(), liquid->offset())
                                          : Grid<float, 3>(*keys.domain, 0.0f);
  std::optional<Grid<float, 3>> temperature, emitter;
  if (hasGrid(grids, keys.temperatureGrid)) temperature = readForRender(frame, keys.temperatureGrid, keys.slabCells);
  if (temperature && hasGrid(grids, keys.emitterGrid)) emitter = readForRender(frame, keys.emitterGrid, keys.slabCells);
  std::optional<Grid<float, 3>> obstacles;
  if (hasGrid(grids, keys.obstacleGrid)) obstacles = readForRender(frame, keys.obstacleGrid, keys.slabCells);
  if (obstacles && !obstacles->sameLayout(density) && obstacles->offset() == density.offset()) {
    // The solids' distance on the simulation grid, the surface on a finer one (a liquid with
    // sub-grid turbulence): the distance resampled onto the surface's cells.
    Grid<float, 3> fine(density.spec(), density.size(), density.offset());
    resampleLinear<3>(*obstacles, fine);
    obstacles = std::move(fine);
  }
  render::FrameSurfaces surfaces;
  surfaces.distance = obstacles ? &*obstacles : nullptr;
  surfaces.liquid = liquid ? &*liquid : nullptr;
  for (const TriangleMesh& mesh : keys.geometry->meshes) surfaces.meshes.push_back(&mesh);
  if (surface) surfaces.meshes.push_back(&*surface);
  if (!keys.geometry->points.empty()) {
    render::PointSet points;
    points.positions = &keys.geometry->points;
    points.radius = keys.geometry->pointRadius;
    points.albedo = keys.geometry->pointAlbedo;
    surfaces.points.push_back(points);
  }
  try {
    const render::FrameResult r = render::renderFrame(keys.config, density, temperature ? &*temperature : nullptr,
                                                      emitter ? &*emitter : nullptr, surfaces);
    if (timings) *timings = r.timings;
    io::writePng(png, r.render.image);
    if (keys.exr) io::writeExr(fs::path(png).replace_extension(".exr"), r.render.radiance);
  } catch (const std::invalid_argument& e) {
    // What the renderer refuses in a valid file (a camera inside an obstacle, grids of different
    // layouts) is an input error of this frame: exit 2 naming it.
    throw InputError(fmt::format("{}: cannot render: {}", vdbFile, e.what()));
  }
}

std::vector<fs::path> renderSavedFrames(const RenderJob& job) {
  std::vector<fs::path> frames;
  // A run folder's frames must be the ones the run wrote; a single file may come from any tool.
  io::VdbProvenance provenance = io::VdbProvenance::MsimRun;
  fs::path outDir;
  RenderKeys keys;
  double fps = 24.0;
  const std::string source = job.input.string();
  if (fs::is_directory(job.input)) {
    const fs::path runFile = job.input / "run.json";
    if (!fs::exists(runFile))
      throw InputError(source + ": not a run folder (no run.json); give a folder written by 'msim run' or a .vdb file");
    const nlohmann::json run = loadJsonFile(runFile);
    // Frames are 1/fps apart in the run; without it in run.json the movie plays at 24 fps.
    fps = run.value("fps", fps);
    const nlohmann::json params = run.value("parameters", nlohmann::json::object());
    // Mesh and point files are named relative to the scene file, as in the scene itself.
    const fs::path sceneFile = run.value("scene_file", std::string());
    keys = jobKeys(params.value("render", nlohmann::json::object()), job.overrides, runFile.string(),
                   sceneFile.parent_path());
    keys.domain = runDomain(run);
    if (fs::is_directory(job.input / "vdb"))
      for (const auto& e : fs::directory_iterator(job.input / "vdb"))
        if (e.path().extension() == ".vdb") frames.push_back(e.path());
    std::sort(frames.begin(), frames.end());
    if (frames.empty()) throw InputError(source + ": the run has no VDB frames (was outputs.vdb false?)");
    if (job.lastFrameOnly) frames.erase(frames.begin(), frames.end() - 1);
    outDir = job.output.empty() ? job.input / "render" : job.output;
  } else if (job.input.extension() == ".vdb") {
    if (!fs::exists(job.input)) throw InputError(source + ": no such file");
    keys = jobKeys(nlohmann::json::object(), job.overrides, source, fs::path());
    frames.push_back(job.input);
    provenance = io::VdbProvenance::AnyTool;
  } else {
    throw InputError(source + ": expected a run folder (with run.json) or a .vdb file");
  }

  std::vector<fs::path> written;
  ProgressBar progress(1, static_cast<int>(frames.size()));
  for (std::size_t i = 0; i < frames.size(); ++i) {
    fs::path target;
    if (outDir.empty()) {
      target = job.output.empty() ? fs::path(job.input).replace_extension(".png") : job.output;
    } else {
      fs::create_directories(outDir);
      target = outDir / frames[i].filename().replace_extension(".png");
    }
    renderSavedFrame(io::VdbFile(frames[i], provenance), keys, target);
    written.push_back(target);
    if (job.showProgress) progress.update(static_cast<int>(i) + 1, 1);
  }
  if (job.showProgress) progress.finish();
  if (!outDir.empty() && written.size() > 1) {
    const io::VideoResult video = io::encodeMp4(written, fps, outDir / "render.mp4");
    if (!video.written) logger().warn("{}", video.note);
  }
  return written;
}

}  // namespace msim::scene
