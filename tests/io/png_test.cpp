#include "msim/io/png.hpp"

#include <gtest/gtest.h>

#include <cmath>

#include "msim/core/error.hpp"
#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::scratchDir;
using test::writeText;

TEST(Png, RoundTripIsExact) {
  const auto dir = scratchDir();
  Image image(7, 5);  // odd sizes catch row-stride mistakes
  for (std::size_t i = 0; i < image.rgb.size(); ++i) image.rgb[i] = static_cast<std::uint8_t>((i * 37 + 11) % 256);
  writePng(dir / "a.png", image);
  const Image back = readPng(dir / "a.png");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgb, image.rgb);
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);
}

TEST(Png, FloatImageConversionClampsAndAppliesGamma) {
  ImageF f(4, 1);
  const float values[4] = {-1.0f, 0.25f, 2.0f, std::nanf("")};
  for (int x = 0; x < 4; ++x)
    for (int c = 0; c < 3; ++c) f.pixel(x, 0)[c] = values[x];
  const Image linear = f.toImage8(1.0);
  EXPECT_EQ(linear.pixel(0, 0)[0], 0);
  EXPECT_EQ(linear.pixel(1, 0)[1], 64);  // round(0.25 * 255)
  EXPECT_EQ(linear.pixel(2, 0)[2], 255);
  EXPECT_EQ(linear.pixel(3, 0)[0], 0);
  EXPECT_EQ(f.toImage8(2.0).pixel(1, 0)[0], 128);  // round(sqrt(0.25) * 255)
}

TEST(Png, BadFilesThrowInputError) {
  const auto dir = scratchDir();
  writeText(dir / "fake.png", "this is not a png");
  expectInputError([&] { readPng(dir / "fake.png"); }, {"fake.png"});
  expectInputError([&] { readPng(dir / "missing.png"); }, {"missing.png"});
}

}  // namespace
}  // namespace msim::io
