#pragma once
// Scene vectors have 2 numbers in 2D scenes and 3 in 3D ones; solvers work with Vec3 and ignore z
// in 2D. This pads a resolved vector with `fill` to three components.
#include <nlohmann/json.hpp>

#include "msim/core/vec.hpp"

namespace msim::scene {

inline Vec3 paddedVec3(const nlohmann::json& v, double fill = 0.0) {
  Vec3 p = Vec3::Constant(fill);
  for (std::size_t i = 0; i < v.size() && i < 3; ++i) p[static_cast<int>(i)] = v[i].get<double>();
  return p;
}

// The first D numbers of a resolved scene vector (2D scenes ignore a z given in a 3-vector).
template <int D>
Vec<D> sceneVector(const nlohmann::json& v) {
  const Vec3 p = paddedVec3(v);
  Vec<D> out;
  for (int a = 0; a < D; ++a) out[a] = p[a];
  return out;
}

}  // namespace msim::scene
