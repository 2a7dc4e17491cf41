#pragma once
// Wavefront OBJ geometry: vertex positions (`v`) and faces (`f`) to and from a TriangleMesh.
// Texture coordinates, normals, groups and materials do not affect the geometry and are ignored.
#include <filesystem>

#include "msim/core/triangle_mesh.hpp"

namespace msim::io {

// Face corners may be written v, v/vt, v//vn or v/vt/vn; negative indices count back from the
// last vertex defined so far. Polygons are fan-triangulated. InputError naming file:line for a
// missing file, a malformed number, an out-of-range index or a face with fewer than 3 corners.
TriangleMesh readObj(const std::filesystem::path& path);

// `v x y z` lines (9 significant digits) and `f a b c` lines (1-based), written atomically (a
// reader never sees half a file). std::invalid_argument for a triangle index out of range,
// std::runtime_error when the file cannot be written.
void writeObj(const std::filesystem::path& path, const TriangleMesh& mesh);

}  // namespace msim::io
