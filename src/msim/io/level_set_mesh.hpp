#pragma once
// The zero surface of a cell-centred level set as a triangle mesh, by OpenVDB's own
// volumeToMesh (dual contouring of the narrow band; quads split into two triangles), in world
// coordinates. Liquids write it per frame as PLY/OBJ for renderers that want a mesh.
#include "msim/core/grid.hpp"
#include "msim/core/triangle_mesh.hpp"

namespace msim::io {

// phi < 0 inside; the band within halfWidth cells of the surface is used. An empty mesh when phi
// has no zero crossing.
TriangleMesh levelSetMesh(const Grid<float, 3>& phi, int halfWidth = 3);

}  // namespace msim::io
