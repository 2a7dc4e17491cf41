// fineDetailShare against pictures whose spectra are known: a uniform picture has none, a slow
// sine (period 32 px, 1/32 cycles per pixel) lies far below half the Nyquist frequency, a fast one
// (period 2.5 px, 0.4 cycles per pixel) far above it, and equal amplitudes of both split the energy.
#include "msim/render/image_detail.hpp"

#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

namespace msim::render {
namespace {

// A grey picture of luminance 0.5 + sum_k a_k sin(2 pi x / period_k) (stripes along x).
io::Image stripes(double slowAmplitude, double fastAmplitude) {
  io::Image picture(160, 96);
  for (int y = 0; y < picture.height; ++y)
    for (int x = 0; x < picture.width; ++x) {
      const double v = 0.5 + slowAmplitude * std::sin(2.0 * std::numbers::pi * x / 32.0) +
                       fastAmplitude * std::sin(2.0 * std::numbers::pi * x / 2.5);
      std::uint8_t* p = picture.pixel(x, y);
      p[0] = p[1] = p[2] = static_cast<std::uint8_t>(std::lround(255.0 * v));
    }
  return picture;
}

TEST(ImageDetail, SharesFollowTheFrequencyOfTheStripes) {
  EXPECT_LT(fineDetailShare(stripes(0.0, 0.0)), 1e-10);  // the mean is removed: only round-off is left
  const double slow = fineDetailShare(stripes(0.3, 0.0));
  const double fast = fineDetailShare(stripes(0.0, 0.3));
  const double both = fineDetailShare(stripes(0.2, 0.2));
  EXPECT_LT(slow, 1e-3);  // what leaks is the 8-bit rounding
  EXPECT_GT(fast, 0.99);
  EXPECT_NEAR(both, 0.5, 0.05);
  std::printf("fine-detail share: slow stripes %.2e, fast %.4f, both %.3f\n", slow, fast, both);
}

TEST(ImageDetail, BoxMeasuresOnlyItsPixels) {
  io::Image picture = stripes(0.3, 0.0);
  // The right half becomes fast stripes; a box on the left half sees none of them.
  const io::Image fast = stripes(0.0, 0.3);
  for (int y = 0; y < picture.height; ++y)
    for (int x = 80; x < picture.width; ++x)
      for (int c = 0; c < 3; ++c) picture.pixel(x, y)[c] = fast.pixel(x, y)[c];
  EXPECT_LT(fineDetailShare(picture, PixelBox{0, 0, 80, 96}), 1e-3);
  EXPECT_GT(fineDetailShare(picture, PixelBox{80, 0, 160, 96}), 0.99);
  EXPECT_THROW(fineDetailShare(picture, PixelBox{0, 0, 161, 96}), std::invalid_argument);
  EXPECT_THROW(fineDetailShare(picture, PixelBox{10, 10, 10, 20}), std::invalid_argument);
}

}  // namespace
}  // namespace msim::render
