#pragma once
// Trilinear sampling of cell-centred grids, shared by the volume renderer's march and the liquid
// surface's level set: the weights of one point are computed once and applied to every grid of
// the same layout (density, temperature, light transmittances, distances).
#include <algorithm>
#include <cstddef>

#include "msim/core/grid.hpp"

namespace msim::render {

// Trilinear interpolation weights of one point, shared by every grid of one layout.
struct Trilinear {
  std::size_t base = 0;
  std::ptrdiff_t ox = 0, oy = 0, oz = 0;  // memory offsets to the upper neighbour on each axis
  float tx = 0, ty = 0, tz = 0;

  float operator()(const float* g) const {
    const float* p = g + base;
    const auto lerp = [](float a, float b, float t) { return a + t * (b - a); };
    const float c00 = lerp(p[0], p[ox], tx), c10 = lerp(p[oy], p[oy + ox], tx);
    const float c01 = lerp(p[oz], p[oz + ox], tx), c11 = lerp(p[oz + oy], p[oz + oy + ox], tx);
    return lerp(lerp(c00, c10, ty), lerp(c01, c11, ty), tz);
  }
};

// Trilinear sampling of cell-centred grids of one layout: cell centre c sits at sample coordinate
// c; positions beyond the outer centres clamp onto them (the border value extends to the faces).
class Sampler {
 public:
  explicit Sampler(const Grid<float, 3>& g)
      : origin_(g.spec().origin), invDx_(1.0 / g.spec().dx), n_(g.size()) {
    for (int a = 0; a < 3; ++a) stride_[a] = g.stride(a);
  }

  Trilinear at(const Vec3& x) const {
    Trilinear w;
    std::ptrdiff_t* offset[3] = {&w.ox, &w.oy, &w.oz};
    float* t[3] = {&w.tx, &w.ty, &w.tz};
    for (int a = 0; a < 3; ++a) {
      if (n_[a] < 2) continue;  // a single layer: constant along this axis
      const double hi = n_[a] - 1;
      double s = (x[a] - origin_[a]) * invDx_ - 0.5;
      s = s > 0.0 ? (s < hi ? s : hi) : 0.0;  // a NaN lands on 0 and can never index outside
      const int i0 = std::min(static_cast<int>(s), n_[a] - 2);
      w.base += static_cast<std::size_t>(i0 * stride_[a]);
      *offset[a] = stride_[a];
      *t[a] = static_cast<float>(s - i0);
    }
    return w;
  }

 private:
  Vec3 origin_;
  double invDx_;
  IVec3 n_;
  std::ptrdiff_t stride_[3];
};

}  // namespace msim::render
