#pragma once
// Random points for the collision tests.
#include "msim/core/rng.hpp"
#include "msim/core/vec.hpp"

namespace msim::solids {

// A point uniform in the cube [-half, half]^3.
inline Vec3 randomVector(Rng& rng, double half) {
  return Vec3(rng.uniform(-half, half), rng.uniform(-half, half), rng.uniform(-half, half));
}

}  // namespace msim::solids
