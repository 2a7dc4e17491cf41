#pragma once
// Schema of a solid shape, shared by every scene element placed in space (sources, obstacles,
// regions). geometry::buildShape turns a resolved shape into a signed-distance Shape.
#include "msim/scene/schema/schema.hpp"

namespace msim::scene {

// Variant on "type": sphere {center, radius}, box {min, max}, capsule {a, b, radius},
// plane {point, normal}, mesh {file, scale, translate}. Positions have 2 or 3 components so the
// same schema serves 2D and 3D scenes; meshes are 3D only.
Schema shapeSchema(std::string description = "solid shape");

}  // namespace msim::scene
