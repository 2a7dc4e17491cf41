#pragma once
// The linear radiance of one pixel of a rendered image, for the render tests.
#include "msim/core/vec.hpp"
#include "msim/io/png.hpp"

namespace msim::render::test {

inline Vec3 pixel(const io::ImageF& image, int x, int y) {
  const float* p = image.pixel(x, y);
  return Vec3(p[0], p[1], p[2]);
}

}  // namespace msim::render::test
