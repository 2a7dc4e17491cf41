#pragma once
// Machinery every grid phenomenon needs between its solver and the scene: the finite-state check
// that names step and field, resuming a grid from a saved frame, the preview settings from
// outputs.preview, and shapes from scene keys with "outside the domain" errors.
#include <array>
#include <filesystem>
#include <memory>
#include <string>
#include <utility>
#include <vector>

#include <nlohmann/json.hpp>

#include "msim/core/block_placement.hpp"
#include "msim/core/domain_split.hpp"
#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/geometry/shape.hpp"
#include "msim/io/vdb.hpp"
#include "msim/io/point_cloud.hpp"
#include "msim/render/density_preview.hpp"

namespace msim::scene {

struct Scene;

// SimulationError naming the step, time, field and first bad cell when `grid` holds NaN or inf.
template <int D>
void requireFinite(const Grid<float, D>& grid, const std::string& field, long stepIndex, double time);

// Copies grid `name` of a saved frame into `target` (a cell or face grid); InputError naming the
// scene and file when the grid is missing or its size differs. A block of a run split among
// processes (`placement`) takes its part of the saved whole grid.
template <int D>
void restoreGrid(const io::VdbFile& saved, const std::string& name, Grid<float, D>& target,
                 const std::string& sceneSource, const BlockPlacement<D>& placement = {});

// MAC face velocities in a frame for --resume: component a as the cell grid "vel_face_<x|y|z>"
// of its own size (VDB files hold cell grids; tools should use the cell-centred "vel").
template <int D>
void writeFaceVelocities(io::VdbWriter& writer, const MacGrid<D>& velocity);
template <int D>
void restoreFaceVelocities(const io::VdbFile& saved, MacGrid<D>& velocity, const std::string& sceneSource,
                           const BlockPlacement<D>& placement = {});

// Point attribute `name` of a cloud read back from a saved frame for --resume; InputError naming
// the scene and file when the cloud has points but not the attribute (an empty list for an empty
// cloud).
const std::vector<float>& savedPointAttribute(const io::PointCloud& cloud, const std::string& name,
                                              const std::filesystem::path& vdbFile, const std::string& sceneSource);

// The keys of domain.boundaries, per axis and side (0 lower, 1 upper).
inline constexpr const char* kDomainSideKeys[3][2] = {{"x_min", "x_max"}, {"y_min", "y_max"}, {"z_min", "z_max"}};

// Which sides of a resolved scene's domain.boundaries are "open", per axis and side.
template <int D>
std::array<std::array<bool, 2>, D> openDomainSides(const nlohmann::json& resolved) {
  std::array<std::array<bool, 2>, D> open{};
  const nlohmann::json& sides = resolved.at("domain").at("boundaries");
  for (int a = 0; a < D; ++a)
    for (int s = 0; s < 2; ++s) open[a][s] = sides.at(kDomainSideKeys[a][s]).template get<std::string>() == "open";
  return open;
}

// outputs.preview of a resolved scene.
render::PreviewSettings previewSettings(const Scene& scene);

// Shape at scene key `key` (e.g. "sources[0].shape").
template <int D>
std::unique_ptr<geometry::Shape<D>> sceneShape(const Scene& scene, const nlohmann::json& shapeJson,
                                               const std::string& key);

// Cells covered by `shape` (coverage in (0,1]) that are not solid; InputError naming `key` when
// there is none (the shape lies outside the domain or inside an obstacle). In a run split among
// processes (`split`), `solid` is the local grid and the error needs no covered cell on any rank.
template <int D>
std::vector<std::pair<std::size_t, float>> coveredOpenCells(const Scene& scene, const geometry::Shape<D>& shape,
                                                            const Grid<float, D>& solid, const std::string& key,
                                                            DomainSplit<D>* split = nullptr);

}  // namespace msim::scene
