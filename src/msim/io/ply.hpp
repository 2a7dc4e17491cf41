#pragma once
// PLY (Stanford polygon) files for point sets and triangle meshes.
// Writers emit binary_little_endian (default) or ascii; the reader accepts both with any of the
// scalar types char/uchar/short/ushort/int/uint/float/double (and their int8..float64 aliases).
// Floats are written exactly (shortest round-trip text in ascii), so float data survive a round
// trip bit-equal. TriangleMesh positions are double: written as float by default (what most tools
// expect), or as double with PlyPositionType::Float64 when the round trip must be exact.
#include <filesystem>
#include <span>
#include <vector>

#include "msim/core/triangle_mesh.hpp"
#include "msim/io/point_cloud.hpp"

namespace msim::io {

enum class PlyEncoding { BinaryLittleEndian, Ascii };
enum class PlyPositionType { Float32, Float64 };

struct PlyWriteOptions {
  PlyEncoding encoding = PlyEncoding::BinaryLittleEndian;
  PlyPositionType positionType = PlyPositionType::Float32;  // meshes only; point clouds are float
};

// Element "vertex" with float x y z and one float property per attribute.
// std::invalid_argument if an attribute has the wrong length or a name that is not a plain
// identifier (or is x, y, z).
void writePlyPoints(const std::filesystem::path& path, const PointCloud& points,
                    PlyEncoding encoding = PlyEncoding::BinaryLittleEndian);

// Vertex x y z plus every other scalar vertex property as a float attribute (in file order).
// InputError naming the file (and line for ascii) for a missing, malformed or truncated file.
PointCloud readPlyPoints(const std::filesystem::path& path);

// Element "vertex" (x y z, then the float vertex attributes) and element "face" with
// `property list uchar int vertex_indices`. std::invalid_argument for out-of-range triangle
// indices or bad attributes (as writePlyPoints).
void writePlyMesh(const std::filesystem::path& path, const TriangleMesh& mesh,
                  std::span<const PointAttribute> vertexAttributes = {}, const PlyWriteOptions& options = {});

struct PlyMesh {
  TriangleMesh mesh;
  std::vector<PointAttribute> vertexAttributes;
};

// Faces with more than three vertices are fan-triangulated. Faces are read from the list property
// vertex_indices (or vertex_index); an index outside the vertex range is an InputError.
PlyMesh readPlyMesh(const std::filesystem::path& path);

}  // namespace msim::io
