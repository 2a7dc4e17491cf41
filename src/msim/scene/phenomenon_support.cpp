#include "msim/scene/phenomenon_support.hpp"

#include <algorithm>
#include <cmath>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/grid_window.hpp"
#include "msim/geometry/occupancy.hpp"
#include "msim/geometry/shape_factory.hpp"
#include "msim/io/vdb.hpp"
#include "msim/scene/scene_file.hpp"

namespace msim::scene {

template <int D>
void requireFinite(const Grid<float, D>& g, const std::string& field, long stepIndex, double time) {
  for (std::size_t i = 0; i < g.count(); ++i) {
    if (std::isfinite(g[i])) continue;
    const IVec<D> c = g.coord(i);
    throw SimulationError(fmt::format("step {} (t = {:.4g} s): field '{}' became {} at cell ({}); the run is unstable",
                                      stepIndex, time, field, g[i], fmt::join(c.data(), c.data() + D, ", ")));
  }
}

template <int D>
void restoreGrid(const io::VdbFile& file, const std::string& name, Grid<float, D>& target,
                 const std::string& sceneSource, const BlockPlacement<D>& placement) {
  const Grid<float, 3> saved = file.floatGrid(name);
  // The file holds the whole grid; a block of a split run takes its part of it.
  const IVec<D> whole = placement.whole() ? target.size() : (placement.globalRes + target.size() - target.spec().res).eval();
  std::size_t count = 1;
  bool same = saved.spec().dx == target.spec().dx;
  for (int a = 0; a < D; ++a) {
    same = same && saved.size()[a] == whole[a];
    count *= static_cast<std::size_t>(whole[a]);
  }
  if (!same || saved.count() != count)
    throw InputError(fmt::format("{}: cannot resume from '{}': its grid '{}' does not match the scene's domain",
                                 sceneSource, file.path().string(), name));
  if (placement.whole()) {
    std::copy(saved.data().begin(), saved.data().end(), target.data().begin());
    return;
  }
  if constexpr (D == 3)  // runs split among processes are 3D
    forEachWindowRow<3>(saved, placement.cellOrigin, target,
                        [](const float* row, float* block, std::size_t n) { std::copy_n(row, n, block); });
  else
    throw std::logic_error("restoreGrid: a block of a 2D grid");
}

const std::vector<float>& savedPointAttribute(const io::PointCloud& cloud, const std::string& name,
                                              const std::filesystem::path& vdbFile, const std::string& sceneSource) {
  const io::PointAttribute* a = cloud.find(name);
  if (!a && !cloud.positions.empty())
    throw InputError(fmt::format("{}: {} has no point attribute '{}' to resume from", sceneSource, vdbFile.string(), name));
  static const std::vector<float> none;
  return a ? a->values : none;
}

render::PreviewSettings previewSettings(const Scene& scene) {
  const nlohmann::json& p = scene.resolved.at("outputs").at("preview");
  auto axis = [](const nlohmann::json& name) { return name.get<std::string>()[0] - 'x'; };
  render::PreviewSettings s;
  s.viewAxis = axis(p.at("view_axis"));
  s.upAxis = axis(p.at("up_axis"));
  if (scene.dimensions == 3 && s.viewAxis == s.upAxis)
    throw InputError(scene.file.string() + ": 'outputs.preview.view_axis' and 'outputs.preview.up_axis' must differ");
  s.extinction = p.at("extinction").get<double>();
  s.albedo = p.at("albedo").get<double>();
  s.minWidth = p.at("width").get<int>();
  return s;
}

namespace {

std::string faceGridName(int axis) { return std::string("vel_face_") + "xyz"[axis]; }

}  // namespace

template <int D>
void writeFaceVelocities(io::VdbWriter& writer, const MacGrid<D>& velocity) {
  for (int a = 0; a < D; ++a) {
    const Grid<float, D>& face = velocity.component(a);
    GridSpec<D> spec = face.spec();
    spec.res = face.size();
    Grid<float, D> cells(spec);
    std::copy(face.data().begin(), face.data().end(), cells.data().begin());
    writer.addFloatGrid(faceGridName(a), cells);
  }
}

template <int D>
void restoreFaceVelocities(const io::VdbFile& saved, MacGrid<D>& velocity, const std::string& sceneSource,
                           const BlockPlacement<D>& placement) {
  for (int a = 0; a < D; ++a) restoreGrid(saved, faceGridName(a), velocity.component(a), sceneSource, placement);
}

template <int D>
std::unique_ptr<geometry::Shape<D>> sceneShape(const Scene& scene, const nlohmann::json& shapeJson,
                                               const std::string& key) {
  return geometry::buildShape<D>(shapeJson, scene.directory(), scene.file.string() + ": " + key);
}

template <int D>
std::vector<std::pair<std::size_t, float>> coveredOpenCells(const Scene& scene, const geometry::Shape<D>& shape,
                                                            const Grid<float, D>& solid, const std::string& key,
                                                            DomainSplit<D>* split) {
  const Grid<float, D> cover = geometry::occupancy(shape, solid.spec());
  std::vector<std::pair<std::size_t, float>> cells;
  for (std::size_t c = 0; c < cover.count(); ++c)
    if (cover[c] > 0.0f && solid[c] < 0.5f) cells.emplace_back(c, cover[c]);
  const double mostCells = static_cast<double>(cells.size());
  if ((split ? split->maxOverRanks(mostCells) : mostCells) == 0.0)
    throw InputError(fmt::format("{}: '{}' covers no open cell of the domain (outside it, or inside an obstacle)",
                                 scene.file.string(), key));
  return cells;
}

#define MSIM_INSTANTIATE(D)                                                                                        \
  template void requireFinite<D>(const Grid<float, D>&, const std::string&, long, double);                          \
  template void restoreGrid<D>(const io::VdbFile&, const std::string&, Grid<float, D>&,                             \
                               const std::string&, const BlockPlacement<D>&);                                    \
  template void writeFaceVelocities<D>(io::VdbWriter&, const MacGrid<D>&);                                         \
  template void restoreFaceVelocities<D>(const io::VdbFile&, MacGrid<D>&, const std::string&,                       \
                                         const BlockPlacement<D>&);                                              \
  template std::unique_ptr<geometry::Shape<D>> sceneShape<D>(const Scene&, const nlohmann::json&,                  \
                                                             const std::string&);                                 \
  template std::vector<std::pair<std::size_t, float>> coveredOpenCells<D>(const Scene&, const geometry::Shape<D>&, \
                                                                          const Grid<float, D>&, const std::string&,  \
                                                                          DomainSplit<D>*);
MSIM_INSTANTIATE(2)
MSIM_INSTANTIATE(3)
#undef MSIM_INSTANTIATE

}  // namespace msim::scene
