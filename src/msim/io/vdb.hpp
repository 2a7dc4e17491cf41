#pragma once
// OpenVDB output and input of msim fields and particles. OpenVDB headers stay in vdb.cpp (they
// are slow to compile), so this interface only speaks msim types.
//
// Grid layout: VDB voxel (i,j,k) is msim cell (i,j,k), and the transform (uniform scale dx,
// translated by origin + dx/2) puts voxel centres exactly on msim cell centres, so tools such as
// Houdini or Blender show the field where msim simulated it. The GridSpec is stored as grid
// metadata (msim_origin, msim_dx, msim_res) and restored exactly on reading.
//
// Grid classes, as Houdini, Blender and OpenVDB's tools expect them:
// - fog volumes (densities, flame, fuel): class "fog volume", background 0; zeros, subnormal values
//   and values at or below the writer's fog tolerance are inactive;
// - level sets (signed distances): class "level set", a narrow band of active voxels within
//   halfWidth voxels of the surface, background +halfWidth*dx outside and -halfWidth*dx inside;
// - plain scalars (temperature, pressure, face velocities): class "unknown"; with the default
//   tolerance 0 only values whose bits equal +0 (the background) become inactive, so they
//   round-trip bit-equal; a positive tolerance also drops |v| <= tolerance;
// - vectors are velocities: vector type "contravariant relative" (they transform as displacements).
// Each grid is marked with its creator (msim and its version); file metadata says which scene,
// frame and time the file holds and in which units.
#include <filesystem>
#include <memory>
#include <string>
#include <vector>

#include "msim/core/grid.hpp"
#include "msim/core/mac_grid.hpp"
#include "msim/io/point_cloud.hpp"

namespace msim::io {

// How a writer stores its grids.
struct VdbWriteOptions {
  // Fog-volume values at or below this are inactive (background 0). Zeros and subnormal values
  // are always inactive; msim's own runs flush subnormals to zero, so 0 loses nothing.
  float fogTolerance = 0.0f;
  // Float and vector grids stored as 16-bit halves: files about half the size, values rounded to
  // 11 significant bits (a run resumed from such frames is no longer bit-exact).
  bool halfFloat = false;
};

// What a file holds, written as file metadata: msim_scene, msim_frame, msim_time [s], msim_units
// and msim_version.
struct VdbFrameInfo {
  std::string scene;
  int frame = 0;
  double time = 0.0;  // [s]
};

// Collects named grids and point sets, then writes them into one .vdb file. Each add*() copies
// the data, so the source may change afterwards. Grid names must be unique and non-empty
// (std::invalid_argument otherwise).
class VdbWriter {
 public:
  explicit VdbWriter(VdbWriteOptions options = {});
  ~VdbWriter();
  VdbWriter(const VdbWriter&) = delete;
  VdbWriter& operator=(const VdbWriter&) = delete;

  // Cell-centred scalar field of class "unknown". A 2D grid becomes a one-voxel-thick 3D grid
  // (z origin 0, z res 1); so do the 2D grids of the other add* functions.
  void addFloatGrid(const std::string& name, const Grid<float, 3>& grid, float tolerance = 0.0f);
  void addFloatGrid(const std::string& name, const Grid<float, 2>& grid, float tolerance = 0.0f);
  // A density-like field (non-negative where it matters) as a fog volume.
  void addFogVolume(const std::string& name, const Grid<float, 3>& grid);
  void addFogVolume(const std::string& name, const Grid<float, 2>& grid);
  // A signed distance [m] (negative inside) as a narrow-band level set; values beyond the band
  // are clamped to +-halfWidth*dx. std::invalid_argument for halfWidth < 1.
  void addLevelSet(const std::string& name, const Grid<float, 3>& distance, int halfWidth = 3);
  void addLevelSet(const std::string& name, const Grid<float, 2>& distance, int halfWidth = 3);
  // Velocity fields as Vec3s grids; tolerance applies to the vector length. A MAC velocity is
  // averaged from its faces to the cell centres.
  void addVectorGrid(const std::string& name, const Grid<Vecf<3>, 3>& grid, float tolerance = 0.0f);
  void addVectorGrid(const std::string& name, const Grid<Vec3, 3>& grid, float tolerance = 0.0f);
  void addVectorGrid(const std::string& name, const MacGrid<3>& velocity, float tolerance = 0.0f);
  // A PointDataGrid with float positions and float attributes; point order is kept. voxelSize
  // only sets how points are bucketed (about 8-16 points per voxel is efficient); it is rounded to
  // a power of two, which makes the world <-> voxel-offset conversion exact, so positions read
  // back bit-equal. std::invalid_argument for non-finite positions or mismatched attributes.
  void addPoints(const std::string& name, const PointCloud& points, double voxelSize);
  // A number stored with the frame as file metadata (msim_state_<name>): state a resumed run needs
  // besides the grids, such as a controller's. std::invalid_argument for an empty or repeated name.
  void addNumber(const std::string& name, double value);

  // Writes all added grids atomically, with the frame's metadata if given, and seals the file with
  // its checksum (vdb_seal.hpp); std::runtime_error if writing fails.
  void write(const std::filesystem::path& path, const VdbFrameInfo* frame = nullptr) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// Whether a .vdb file must carry msim's checksum (vdb_seal.hpp) to be read.
enum class VdbProvenance {
  MsimRun,  // a frame of an msim run (render of a run folder, --resume): refused without a matching seal
  AnyTool,  // a file the user names: a seal, if present, must match; a file without one (written by
            // another tool) is parsed by OpenVDB as it is, which trusts the sizes stored in it
};

// A .vdb file read whole, checked and parsed once; its grids are then copied out by name.
// InputError naming the file for a missing, unreadable, damaged or unsealed (MsimRun) file, and
// from the accessors for a missing grid, a grid of another type or an unsupported transform.
class VdbFile {
 public:
  VdbFile(const std::filesystem::path& path, VdbProvenance provenance);
  ~VdbFile();
  VdbFile(VdbFile&&) noexcept;
  VdbFile& operator=(VdbFile&&) noexcept;

  const std::filesystem::path& path() const;
  // Names of the grids, in file order.
  std::vector<std::string> gridNames() const;
  bool hasGrid(const std::string& name) const;
  // A float grid. Grids written by msim get their GridSpec back exactly; other grids get one
  // covering their active voxels (voxel size from the transform, which must be uniform and
  // axis-aligned). Inactive voxels read as the background (0), except in level sets, where they
  // keep their sign (+-half width).
  Grid<float, 3> floatGrid(const std::string& name) const;
  // A Vec3s (or Vec3d, converted to float) grid, as floatGrid.
  Grid<Vecf<3>, 3> vectorGrid(const std::string& name) const;
  // A point set: positions and every float attribute, in the original order for points written by
  // msim. An empty set comes back without attributes (VDB keeps attribute names in the leaves, and
  // an empty grid has none).
  PointCloud points(const std::string& name) const;
  // A number stored by VdbWriter::addNumber; InputError naming the file if it has none of that name.
  double number(const std::string& name) const;

 private:
  struct Impl;
  std::unique_ptr<Impl> impl_;
};

// One-grid shorthands for VdbFile(path, provenance).gridNames(), .floatGrid(name) and so on.
std::vector<std::string> listVdbGrids(const std::filesystem::path& path,
                                      VdbProvenance provenance = VdbProvenance::AnyTool);
Grid<float, 3> readFloatGrid(const std::filesystem::path& path, const std::string& name,
                             VdbProvenance provenance = VdbProvenance::AnyTool);
Grid<Vecf<3>, 3> readVectorGrid(const std::filesystem::path& path, const std::string& name,
                                VdbProvenance provenance = VdbProvenance::AnyTool);
PointCloud readPoints(const std::filesystem::path& path, const std::string& name,
                      VdbProvenance provenance = VdbProvenance::AnyTool);

}  // namespace msim::io
