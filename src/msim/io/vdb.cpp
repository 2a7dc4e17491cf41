#include "msim/io/vdb.hpp"

#include <openvdb/io/Stream.h>
#include <openvdb/openvdb.h>
#include <openvdb/points/PointAttribute.h>
#include <openvdb/points/PointConversion.h>
#include <openvdb/points/PointCount.h>
#include <openvdb/points/PointDataGrid.h>
#include <openvdb/tools/Dense.h>
#include <openvdb/tools/PointIndexGrid.h>
#include <openvdb/tools/SignedFloodFill.h>
#include <tbb/parallel_for.h>

#include <algorithm>
#include <bit>
#include <cmath>
#include <cstdint>
#include <fstream>
#include <mutex>
#include <numeric>
#include <set>
#include <sstream>
#include <stdexcept>

#include <fmt/format.h>

#include "msim/core/error.hpp"
#include "msim/core/system_memory.hpp"
#include "msim/io/atomic_file.hpp"
#include "msim/io/vdb_seal.hpp"
#include "msim/version.hpp"

namespace msim::io {

namespace {

constexpr const char* kMetaOrigin = "msim_origin";
constexpr const char* kMetaDx = "msim_dx";
constexpr const char* kMetaRes = "msim_res";
// Points are stored bucketed by voxel; this attribute remembers each point's original position
// in the cloud so reading restores the caller's order.
constexpr const char* kPointIndexAttribute = "msim_index";
constexpr const char* kUnits = "SI: m, s, kg, K; densities kg/m^3, velocities m/s";

void initializeOpenVdb() {
  static std::once_flag once;
  std::call_once(once, [] { openvdb::initialize(); });
}

openvdb::math::Transform::Ptr cellCentredTransform(const GridSpec<3>& spec) {
  auto xform = openvdb::math::Transform::createLinearTransform(spec.dx);
  const Vec3 firstCentre = spec.cellCenter(IVec3::Zero());
  xform->postTranslate(openvdb::Vec3d(firstCentre.x(), firstCentre.y(), firstCentre.z()));
  return xform;
}

void storeSpec(openvdb::GridBase& grid, const GridSpec<3>& spec) {
  grid.insertMeta(kMetaOrigin, openvdb::Vec3DMetadata(openvdb::Vec3d(spec.origin.x(), spec.origin.y(), spec.origin.z())));
  grid.insertMeta(kMetaDx, openvdb::DoubleMetadata(spec.dx));
  grid.insertMeta(kMetaRes, openvdb::Vec3IMetadata(openvdb::Vec3i(spec.res.x(), spec.res.y(), spec.res.z())));
}

GridSpec<3> toSpec3(const GridSpec<2>& s) {
  return GridSpec<3>(Vec3(s.origin.x(), s.origin.y(), 0.0), s.dx, IVec3(s.res.x(), s.res.y(), 1));
}

bool isPositiveZero(float v) { return std::bit_cast<std::uint32_t>(v) == 0u; }

// Fog volumes keep values above the tolerance that are normal floats (zeros and subnormals go).
bool keepFog(float v, float tolerance) { return std::abs(v) > tolerance && std::isnormal(v); }

bool keepScalar(float v, float tolerance) { return tolerance > 0.0f ? !(std::abs(v) <= tolerance) : !isPositiveZero(v); }

bool keepVector(const openvdb::Vec3f& v, float tolerance) {
  if (tolerance > 0.0f) return !(v.length() <= tolerance);
  return !(isPositiveZero(v[0]) && isPositiveZero(v[1]) && isPositiveZero(v[2]));
}

// Builds a sparse grid from a dense x-fastest array of res cells, one leaf-sized block per task.
// Values for which keep() is false stay background and inactive.
template <typename GridT, typename ValueAt, typename Keep>
typename GridT::Ptr buildSparse(const IVec3& res, ValueAt valueAt, Keep keep,
                                typename GridT::ValueType background = openvdb::zeroVal<typename GridT::ValueType>()) {
  using TreeT = typename GridT::TreeType;
  using LeafT = typename TreeT::LeafNodeType;
  using ValueT = typename GridT::ValueType;
  constexpr int kDim = static_cast<int>(LeafT::DIM);
  const IVec3 blocks = (res.array() + kDim - 1) / kDim;
  const std::size_t blockCount = static_cast<std::size_t>(blocks.x()) * blocks.y() * blocks.z();
  std::vector<std::unique_ptr<LeafT>> leaves(blockCount);
  tbb::parallel_for(std::size_t(0), blockCount, [&](std::size_t b) {
    const int bx = static_cast<int>(b % blocks.x());
    const int by = static_cast<int>((b / blocks.x()) % blocks.y());
    const int bz = static_cast<int>(b / (static_cast<std::size_t>(blocks.x()) * blocks.y()));
    const openvdb::Coord lower(bx * kDim, by * kDim, bz * kDim);
    std::unique_ptr<LeafT> leaf;
    for (int z = lower.z(); z < std::min(lower.z() + kDim, res.z()); ++z)
      for (int y = lower.y(); y < std::min(lower.y() + kDim, res.y()); ++y)
        for (int x = lower.x(); x < std::min(lower.x() + kDim, res.x()); ++x) {
          const IVec3 c(x, y, z);
          const std::size_t linear = (static_cast<std::size_t>(z) * res.y() + y) * res.x() + x;
          const ValueT v = valueAt(c, linear);
          if (!keep(v)) continue;
          if (!leaf) leaf = std::make_unique<LeafT>(lower, background, false);
          leaf->setValueOn(openvdb::Coord(x, y, z), v);
        }
    leaves[b] = std::move(leaf);
  });
  auto tree = std::make_shared<TreeT>(background);
  for (auto& leaf : leaves)
    if (leaf) tree->addLeaf(leaf.release());
  return GridT::create(tree);
}

openvdb::Vec3f toVdb(const Vecf<3>& v) { return {v.x(), v.y(), v.z()}; }

// ---- reading ----

[[noreturn]] void failRead(const std::filesystem::path& path, const std::string& what) {
  throw InputError(path.string() + ": " + what);
}

// The whole file in memory. Its size is checked first: the bytes have to fit in memory beside
// the grids parsed from them.
std::string readFileBytes(const std::filesystem::path& path) {
  std::error_code error;
  const std::uintmax_t size = std::filesystem::file_size(path, error);
  if (error) failRead(path, "cannot read VDB file (" + error.message() + ")");
  const double available = double(availableMemoryBytes());
  if (available > 0.0 && double(size) > 0.5 * available)
    failRead(path, fmt::format("the file is {}, more than half of the {} of memory available", formatBytes(double(size)),
                               formatBytes(available)));
  std::string bytes(static_cast<std::size_t>(size), '\0');
  std::ifstream in(path, std::ios::binary);
  if (!in.read(bytes.data(), static_cast<std::streamsize>(bytes.size())))
    failRead(path, "cannot read VDB file (read failed)");
  return bytes;
}

// The file metadata key of a number added with VdbWriter::addNumber.
std::string numberKey(const std::string& name) { return "msim_state_" + name; }

// A file's grids and its metadata.
struct ParsedVdb {
  openvdb::GridPtrVec grids;
  openvdb::MetaMap::Ptr metadata;
};

// Parses every grid of the file's bytes, and the file's metadata. The stream throws at the end of
// the data, so a count read from a damaged file cannot make OpenVDB loop on past it.
ParsedVdb parseGrids(std::string bytes, const std::filesystem::path& path) {
  initializeOpenVdb();
  try {
    std::istringstream stream(std::move(bytes));
    stream.exceptions(std::ios::failbit | std::ios::badbit);
    openvdb::io::Stream archive(stream, /*delayLoad=*/false);
    ParsedVdb parsed;
    for (const auto& grid : *archive.getGrids())
      if (grid) parsed.grids.push_back(grid);
    parsed.metadata = archive.getMetadata();
    return parsed;
  } catch (const std::exception& e) {  // openvdb::Exception, a stream error or bad_alloc on a corrupt file
    failRead(path, std::string("cannot read VDB file (") + e.what() + ")");
  }
}

// Where the grid's voxels go in the returned msim grid: msim cell = voxel - shift.
struct Placement {
  GridSpec<3> spec;
  openvdb::Coord shift;
};

Placement placementOf(const openvdb::GridBase& grid, const std::filesystem::path& path) {
  const auto origin = grid.getMetadata<openvdb::Vec3DMetadata>(kMetaOrigin);
  const auto dx = grid.getMetadata<openvdb::DoubleMetadata>(kMetaDx);
  const auto res = grid.getMetadata<openvdb::Vec3IMetadata>(kMetaRes);
  constexpr double kMaxCells = 1ull << 34;  // rejects corrupt metadata before a huge allocation
  if (origin && dx && res) {
    const openvdb::Vec3i r = res->value();
    if (r.x() <= 0 || r.y() <= 0 || r.z() <= 0 || double(r.x()) * r.y() * r.z() > kMaxCells || !(dx->value() > 0))
      failRead(path, "grid '" + grid.getName() + "' has invalid msim_res/msim_dx metadata");
    const openvdb::Vec3d o = origin->value();
    return {GridSpec<3>(Vec3(o.x(), o.y(), o.z()), dx->value(), IVec3(r.x(), r.y(), r.z())), openvdb::Coord(0)};
  }
  // A grid from another tool: cover its active voxels; this needs an axis-aligned uniform grid.
  const openvdb::math::Transform& xform = grid.transform();
  const double voxel = xform.voxelSize()[0];
  const openvdb::Vec3d zero = xform.indexToWorld(openvdb::Vec3d(0.0));
  for (int a = 0; a < 3; ++a) {
    openvdb::Vec3d unit(0.0);
    unit[a] = 1.0;
    const openvdb::Vec3d step = xform.indexToWorld(unit) - zero;
    for (int b = 0; b < 3; ++b)
      if (!xform.isLinear() || std::abs(step[b] - (a == b ? voxel : 0.0)) > 1e-9 * voxel)
        failRead(path, "grid '" + grid.getName() + "' has a transform that is not a uniform axis-aligned scale");
  }
  openvdb::CoordBBox box = grid.evalActiveVoxelBoundingBox();
  if (box.empty()) box = openvdb::CoordBBox(openvdb::Coord(0), openvdb::Coord(0));
  const openvdb::Coord dim = box.dim();
  if (double(dim.x()) * dim.y() * dim.z() > kMaxCells)
    failRead(path, "grid '" + grid.getName() + "' is too large to read densely");
  const openvdb::Vec3d corner = xform.indexToWorld(box.min().asVec3d() - openvdb::Vec3d(0.5));
  return {GridSpec<3>(Vec3(corner.x(), corner.y(), corner.z()), voxel, IVec3(dim.x(), dim.y(), dim.z())), box.min()};
}

// Copies the active values (leaf voxels and tiles) of tree into a dense grid of placement's
// layout via store(linear, value). Active values outside the layout are dropped.
template <typename TreeT, typename Store>
void copyActiveValues(const TreeT& tree, const Placement& placement, Store store) {
  const IVec3& res = placement.spec.res;
  const auto linearOf = [&](const openvdb::Coord& voxel, std::size_t& linear) {
    const openvdb::Coord c = voxel - placement.shift;
    if (c.x() < 0 || c.y() < 0 || c.z() < 0 || c.x() >= res.x() || c.y() >= res.y() || c.z() >= res.z()) return false;
    linear = (static_cast<std::size_t>(c.z()) * res.y() + c.y()) * res.x() + c.x();
    return true;
  };
  std::vector<const typename TreeT::LeafNodeType*> leaves;
  tree.getNodes(leaves);
  tbb::parallel_for(std::size_t(0), leaves.size(), [&](std::size_t l) {
    for (auto it = leaves[l]->cbeginValueOn(); it; ++it) {
      std::size_t linear = 0;
      if (linearOf(it.getCoord(), linear)) store(linear, *it);
    }
  });
  typename TreeT::ValueOnCIter tiles = tree.cbeginValueOn();
  tiles.setMaxDepth(TreeT::ValueOnCIter::LEAF_DEPTH - 1);
  for (; tiles; ++tiles) {
    const openvdb::CoordBBox box = tiles.getBoundingBox();
    for (auto ijk = box.begin(); ijk; ++ijk) {
      std::size_t linear = 0;
      if (linearOf(*ijk, linear)) store(linear, *tiles);
    }
  }
}

template <typename VdbGridT>
Grid<Vecf<3>, 3> readVectorGridAs(const VdbGridT& grid, const std::filesystem::path& path) {
  const Placement placement = placementOf(grid, path);
  Grid<Vecf<3>, 3> out(placement.spec, Vecf<3>::Zero());
  copyActiveValues(grid.tree(), placement, [&](std::size_t linear, const typename VdbGridT::ValueType& v) {
    out[linear] = Vecf<3>(static_cast<float>(v[0]), static_cast<float>(v[1]), static_cast<float>(v[2]));
  });
  return out;
}

}  // namespace

struct VdbWriter::Impl {
  VdbWriteOptions options;
  openvdb::GridPtrVec grids;
  std::set<std::string> names;
  openvdb::MetaMap numbers;

  void add(const std::string& name, openvdb::GridBase::Ptr grid) {
    if (name.empty()) throw std::invalid_argument("VdbWriter: empty grid name");
    if (!names.insert(name).second) throw std::invalid_argument("VdbWriter: duplicate grid name '" + name + "'");
    grid->setName(name);
    grid->setCreator(std::string("msim ") + kVersion);
    grid->setSaveFloatAsHalf(options.halfFloat);
    grids.push_back(std::move(grid));
  }

  // A float grid on spec's cells, values from the x-fastest array `values`.
  template <typename Keep>
  void addScalar(const std::string& name, const GridSpec<3>& spec, const std::vector<float>& values, Keep keep,
                 openvdb::GridClass gridClass, float background = 0.0f) {
    auto vdb = buildSparse<openvdb::FloatGrid>(
        spec.res, [&](const IVec3&, std::size_t linear) { return values[linear]; }, keep, background);
    vdb->setTransform(cellCentredTransform(spec));
    vdb->setGridClass(gridClass);
    storeSpec(*vdb, spec);
    add(name, vdb);
  }

  void addFog(const std::string& name, const GridSpec<3>& spec, const std::vector<float>& values) {
    addScalar(name, spec, values, [tolerance = options.fogTolerance](float v) { return keepFog(v, tolerance); },
              openvdb::GRID_FOG_VOLUME);
  }

  // The narrow band |phi| < halfWidth*dx is active; signedFloodFill then gives the inactive
  // voxels and tiles the sign of their side, as OpenVDB's level-set tools require.
  void addLevelSet(const std::string& name, const GridSpec<3>& spec, const std::vector<float>& distance, int halfWidth) {
    if (halfWidth < 1) throw std::invalid_argument("VdbWriter: level set '" + name + "' needs a half width >= 1");
    const float band = static_cast<float>(halfWidth * spec.dx);
    addScalar(name, spec, distance, [band](float v) { return std::abs(v) < band; }, openvdb::GRID_LEVEL_SET, band);
    auto& grid = static_cast<openvdb::FloatGrid&>(*grids.back());
    openvdb::tools::signedFloodFill(grid.tree());
  }

  void addVelocity(const std::string& name, const GridSpec<3>& spec, openvdb::Vec3SGrid::Ptr vdb) {
    vdb->setTransform(cellCentredTransform(spec));
    vdb->setVectorType(openvdb::VEC_CONTRAVARIANT_RELATIVE);
    storeSpec(*vdb, spec);
    add(name, vdb);
  }
};

VdbWriter::VdbWriter(VdbWriteOptions options) : impl_(std::make_unique<Impl>()) {
  if (!(options.fogTolerance >= 0.0f)) throw std::invalid_argument("VdbWriter: the fog tolerance must be >= 0");
  impl_->options = options;
  initializeOpenVdb();
}
VdbWriter::~VdbWriter() = default;

void VdbWriter::addFloatGrid(const std::string& name, const Grid<float, 3>& grid, float tolerance) {
  impl_->addScalar(name, grid.spec(), grid.data(), [&](float v) { return keepScalar(v, tolerance); },
                   openvdb::GRID_UNKNOWN);
}

void VdbWriter::addFloatGrid(const std::string& name, const Grid<float, 2>& grid, float tolerance) {
  impl_->addScalar(name, toSpec3(grid.spec()), grid.data(), [&](float v) { return keepScalar(v, tolerance); },
                   openvdb::GRID_UNKNOWN);
}

void VdbWriter::addFogVolume(const std::string& name, const Grid<float, 3>& grid) {
  impl_->addFog(name, grid.spec(), grid.data());
}

void VdbWriter::addFogVolume(const std::string& name, const Grid<float, 2>& grid) {
  impl_->addFog(name, toSpec3(grid.spec()), grid.data());
}

void VdbWriter::addLevelSet(const std::string& name, const Grid<float, 3>& distance, int halfWidth) {
  impl_->addLevelSet(name, distance.spec(), distance.data(), halfWidth);
}

void VdbWriter::addLevelSet(const std::string& name, const Grid<float, 2>& distance, int halfWidth) {
  impl_->addLevelSet(name, toSpec3(distance.spec()), distance.data(), halfWidth);
}

void VdbWriter::addVectorGrid(const std::string& name, const Grid<Vecf<3>, 3>& grid, float tolerance) {
  impl_->addVelocity(name, grid.spec(),
                     buildSparse<openvdb::Vec3SGrid>(
                         grid.size(), [&](const IVec3&, std::size_t linear) { return toVdb(grid[linear]); },
                         [&](const openvdb::Vec3f& v) { return keepVector(v, tolerance); }));
}

void VdbWriter::addVectorGrid(const std::string& name, const Grid<Vec3, 3>& grid, float tolerance) {
  impl_->addVelocity(name, grid.spec(),
                     buildSparse<openvdb::Vec3SGrid>(
                         grid.size(), [&](const IVec3&, std::size_t linear) { return toVdb(grid[linear].cast<float>()); },
                         [&](const openvdb::Vec3f& v) { return keepVector(v, tolerance); }));
}

void VdbWriter::addVectorGrid(const std::string& name, const MacGrid<3>& velocity, float tolerance) {
  const auto centre = [&](const IVec3& c, std::size_t) {
    openvdb::Vec3f v;
    for (int a = 0; a < 3; ++a) {
      IVec3 upper = c;
      upper[a] += 1;
      v[a] = 0.5f * (velocity.component(a)(c) + velocity.component(a)(upper));
    }
    return v;
  };
  impl_->addVelocity(name, velocity.spec(),
                     buildSparse<openvdb::Vec3SGrid>(velocity.spec().res, centre,
                                                     [&](const openvdb::Vec3f& v) { return keepVector(v, tolerance); }));
}

void VdbWriter::addPoints(const std::string& name, const PointCloud& points, double voxelSize) {
  const std::size_t n = points.positions.size();
  if (!(voxelSize > 0) || !std::isfinite(voxelSize))
    throw std::invalid_argument("VdbWriter: points '" + name + "' need a positive voxel size");
  std::set<std::string> attributeNames{"P", kPointIndexAttribute};
  for (const auto& a : points.attributes) {
    if (a.values.size() != n)
      throw std::invalid_argument("VdbWriter: attribute '" + a.name + "' of points '" + name + "' has " +
                                  std::to_string(a.values.size()) + " values for " + std::to_string(n) + " points");
    if (a.name.empty() || !attributeNames.insert(a.name).second)
      throw std::invalid_argument("VdbWriter: attribute name '" + a.name + "' of points '" + name +
                                  "' is empty, reserved or repeated");
  }
  std::vector<openvdb::Vec3f> positions(n);
  for (std::size_t i = 0; i < n; ++i) {
    if (!points.positions[i].allFinite())
      throw std::invalid_argument("VdbWriter: point " + std::to_string(i) + " of '" + name + "' is not finite");
    positions[i] = toVdb(points.positions[i]);
  }
  const double powerOfTwoVoxel = std::exp2(std::round(std::log2(voxelSize)));
  const auto xform = openvdb::math::Transform::createLinearTransform(powerOfTwoVoxel);
  const openvdb::points::PointAttributeVector<openvdb::Vec3f> positionWrapper(positions);
  const auto indexGrid = openvdb::tools::createPointIndexGrid<openvdb::tools::PointIndexGrid>(positionWrapper, *xform);
  // NullCodec stores the voxel-local offsets as plain floats (no quantisation).
  auto grid = openvdb::points::createPointDataGrid<openvdb::points::NullCodec, openvdb::points::PointDataGrid>(
      *indexGrid, positionWrapper, *xform);
  auto& tree = grid->tree();

  std::vector<std::int64_t> order(n);
  std::iota(order.begin(), order.end(), std::int64_t{0});
  openvdb::points::appendAttribute<std::int64_t>(tree, kPointIndexAttribute);
  openvdb::points::populateAttribute(tree, indexGrid->tree(), kPointIndexAttribute,
                                     openvdb::points::PointAttributeVector<std::int64_t>(order));
  for (const auto& a : points.attributes) {
    openvdb::points::appendAttribute<float>(tree, a.name);
    openvdb::points::populateAttribute(tree, indexGrid->tree(), a.name,
                                       openvdb::points::PointAttributeVector<float>(a.values));
  }
  impl_->add(name, grid);
}

void VdbWriter::addNumber(const std::string& name, double value) {
  if (name.empty()) throw std::invalid_argument("VdbWriter: empty number name");
  if (impl_->numbers[numberKey(name)]) throw std::invalid_argument("VdbWriter: duplicate number name '" + name + "'");
  impl_->numbers.insertMeta(numberKey(name), openvdb::DoubleMetadata(value));
}

void VdbWriter::write(const std::filesystem::path& path, const VdbFrameInfo* frame) const {
  writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
    try {
      openvdb::io::File file(tmp.string());
      openvdb::MetaMap fileMetadata(impl_->numbers);
      fileMetadata.insertMeta("msim_version", openvdb::StringMetadata(kVersion));
      fileMetadata.insertMeta("msim_units", openvdb::StringMetadata(kUnits));
      if (frame) {
        fileMetadata.insertMeta("msim_scene", openvdb::StringMetadata(frame->scene));
        fileMetadata.insertMeta("msim_frame", openvdb::Int32Metadata(frame->frame));
        fileMetadata.insertMeta("msim_time", openvdb::DoubleMetadata(frame->time));
      }
      fileMetadata.insertMeta(kVdbSealKey, openvdb::StringMetadata(kVdbSealPlaceholder));
      file.write(impl_->grids, fileMetadata);
      file.close();
      sealVdbFile(tmp);
    } catch (const openvdb::Exception& e) {
      throw std::runtime_error("cannot write " + path.string() + ": " + e.what());
    }
  });
}

struct VdbFile::Impl {
  std::filesystem::path path;
  openvdb::GridPtrVec grids;
  openvdb::MetaMap::Ptr metadata;

  openvdb::GridBase::Ptr grid(const std::string& name) const {
    for (const auto& g : grids)
      if (g->getName() == name) return g;
    std::string names;
    for (const auto& g : grids) names += (names.empty() ? "" : ", ") + g->getName();
    failRead(path, "no grid named '" + name + "' (the file has: " + (names.empty() ? "none" : names) + ")");
  }

  template <typename GridT>
  typename GridT::Ptr gridOfType(const std::string& name) const {
    auto base = grid(name);
    auto typed = openvdb::gridPtrCast<GridT>(base);
    if (!typed)
      failRead(path, "grid '" + name + "' has type " + base->valueType() + ", expected " +
                         openvdb::typeNameAsString<typename GridT::ValueType>());
    return typed;
  }
};

VdbFile::VdbFile(const std::filesystem::path& path, VdbProvenance provenance) : impl_(std::make_unique<Impl>()) {
  impl_->path = path;
  std::string bytes = readFileBytes(path);
  // The seal is checked before OpenVDB reads a byte: a damaged frame never reaches its parser.
  if (checkVdbSeal(bytes, path) == VdbSeal::Absent && provenance == VdbProvenance::MsimRun)
    failRead(path, "not a frame written by this version of msim, or damaged: it carries no msim checksum");
  ParsedVdb parsed = parseGrids(std::move(bytes), path);
  impl_->grids = std::move(parsed.grids);
  impl_->metadata = std::move(parsed.metadata);
}

VdbFile::~VdbFile() = default;
VdbFile::VdbFile(VdbFile&&) noexcept = default;
VdbFile& VdbFile::operator=(VdbFile&&) noexcept = default;

const std::filesystem::path& VdbFile::path() const { return impl_->path; }

std::vector<std::string> VdbFile::gridNames() const {
  std::vector<std::string> names;
  for (const auto& g : impl_->grids) names.push_back(g->getName());
  return names;
}

bool VdbFile::hasGrid(const std::string& name) const {
  return std::any_of(impl_->grids.begin(), impl_->grids.end(), [&](const auto& g) { return g->getName() == name; });
}

Grid<float, 3> VdbFile::floatGrid(const std::string& name) const {
  const auto grid = impl_->gridOfType<openvdb::FloatGrid>(name);
  const Placement placement = placementOf(*grid, impl_->path);
  Grid<float, 3> out(placement.spec, 0.0f);
  if (grid->getGridClass() == openvdb::GRID_LEVEL_SET) {
    // Inactive voxels of a level set carry the sign of their side: copy every value. Dense's
    // LayoutXYZ (x fastest) is msim's cell order.
    const IVec3& res = placement.spec.res;
    const openvdb::CoordBBox box(placement.shift, placement.shift + openvdb::Coord(res.x() - 1, res.y() - 1, res.z() - 1));
    openvdb::tools::Dense<float, openvdb::tools::LayoutXYZ> dense(box, out.data().data());
    openvdb::tools::copyToDense(*grid, dense);
    return out;
  }
  copyActiveValues(grid->tree(), placement, [&](std::size_t linear, float v) { out[linear] = v; });
  return out;
}

Grid<Vecf<3>, 3> VdbFile::vectorGrid(const std::string& name) const {
  const auto base = impl_->grid(name);
  if (const auto vs = openvdb::gridPtrCast<openvdb::Vec3SGrid>(base)) return readVectorGridAs(*vs, impl_->path);
  if (const auto vd = openvdb::gridPtrCast<openvdb::Vec3DGrid>(base)) return readVectorGridAs(*vd, impl_->path);
  failRead(impl_->path, "grid '" + name + "' has type " + base->valueType() + ", expected vec3s or vec3d");
}

double VdbFile::number(const std::string& name) const {
  const auto value = impl_->metadata ? impl_->metadata->getMetadata<openvdb::DoubleMetadata>(numberKey(name)) : nullptr;
  if (!value) failRead(impl_->path, "no number named '" + name + "' in its metadata");
  return value->value();
}

PointCloud VdbFile::points(const std::string& name) const {
  using openvdb::points::PointDataGrid;
  const auto grid = impl_->gridOfType<PointDataGrid>(name);
  const std::filesystem::path& path = impl_->path;
  const auto& tree = grid->tree();
  PointCloud cloud;
  const auto firstLeaf = tree.cbeginLeaf();
  if (!firstLeaf) return cloud;

  const auto& descriptor = firstLeaf->attributeSet().descriptor();
  const std::size_t positionIndex = descriptor.find("P");
  if (positionIndex == openvdb::points::AttributeSet::INVALID_POS)
    failRead(path, "points '" + name + "' have no position attribute P");
  const std::size_t orderIndex = descriptor.find(kPointIndexAttribute);
  const bool hasOrder = orderIndex != openvdb::points::AttributeSet::INVALID_POS &&
                        descriptor.valueType(orderIndex) == openvdb::typeNameAsString<std::int64_t>();
  // Only float attributes map onto PointAttribute; others (groups, ints, strings) are skipped.
  std::vector<std::pair<std::string, std::size_t>> floatAttributes;
  for (const auto& [attributeName, index] : descriptor.map())
    if (index != positionIndex && descriptor.valueType(index) == openvdb::typeNameAsString<float>())
      floatAttributes.emplace_back(attributeName, index);
  std::sort(floatAttributes.begin(), floatAttributes.end(), [](const auto& a, const auto& b) { return a.second < b.second; });

  std::vector<const PointDataGrid::TreeType::LeafNodeType*> leaves;
  tree.getNodes(leaves);
  std::vector<std::size_t> firstPoint(leaves.size() + 1, 0);
  for (std::size_t l = 0; l < leaves.size(); ++l) firstPoint[l + 1] = firstPoint[l] + leaves[l]->pointCount();
  const std::size_t n = firstPoint.back();
  cloud.positions.resize(n);
  for (const auto& [attributeName, index] : floatAttributes) cloud.attributes.push_back({attributeName, std::vector<float>(n)});

  const openvdb::math::Transform& xform = grid->transform();
  tbb::parallel_for(std::size_t(0), leaves.size(), [&](std::size_t l) {
    const auto& leaf = *leaves[l];
    if (!(leaf.attributeSet().descriptor() == descriptor))
      failRead(path, "points '" + name + "' have leaves with different attribute layouts");
    openvdb::points::AttributeHandle<openvdb::Vec3f> position(leaf.constAttributeArray(positionIndex));
    std::unique_ptr<openvdb::points::AttributeHandle<std::int64_t>> order;
    if (hasOrder) order = std::make_unique<openvdb::points::AttributeHandle<std::int64_t>>(leaf.constAttributeArray(orderIndex));
    std::vector<openvdb::points::AttributeHandle<float>> values;
    for (const auto& [attributeName, index] : floatAttributes) values.emplace_back(leaf.constAttributeArray(index));
    std::size_t next = firstPoint[l];
    for (auto it = leaf.beginIndexAll(); it; ++it, ++next) {
      const openvdb::Index p = *it;
      std::size_t slot = next;
      if (order) {
        const std::int64_t original = order->get(p);
        if (original < 0 || static_cast<std::size_t>(original) >= n)
          failRead(path, "points '" + name + "' have an invalid " + kPointIndexAttribute + " value");
        slot = static_cast<std::size_t>(original);
      }
      // Index space = voxel + stored offset; with msim's power-of-two voxel size this is exact.
      // In voxel 0 the offset is used alone, because 0 + (-0) would turn a -0 coordinate into +0.
      const openvdb::Coord voxel = it.getCoord();
      const openvdb::Vec3f offset = position.get(p);
      openvdb::Vec3d index;
      for (int a = 0; a < 3; ++a) index[a] = voxel[a] == 0 ? double(offset[a]) : voxel[a] + double(offset[a]);
      const openvdb::Vec3d world = xform.indexToWorld(index);
      cloud.positions[slot] = Vecf<3>(static_cast<float>(world.x()), static_cast<float>(world.y()), static_cast<float>(world.z()));
      for (std::size_t a = 0; a < values.size(); ++a) cloud.attributes[a].values[slot] = values[a].get(p);
    }
  });
  return cloud;
}

std::vector<std::string> listVdbGrids(const std::filesystem::path& path, VdbProvenance provenance) {
  return VdbFile(path, provenance).gridNames();
}

Grid<float, 3> readFloatGrid(const std::filesystem::path& path, const std::string& name, VdbProvenance provenance) {
  return VdbFile(path, provenance).floatGrid(name);
}

Grid<Vecf<3>, 3> readVectorGrid(const std::filesystem::path& path, const std::string& name,
                                VdbProvenance provenance) {
  return VdbFile(path, provenance).vectorGrid(name);
}

PointCloud readPoints(const std::filesystem::path& path, const std::string& name, VdbProvenance provenance) {
  return VdbFile(path, provenance).points(name);
}

}  // namespace msim::io
