#include "msim/io/exr.hpp"

#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>

#include "scratch_dir.hpp"

namespace msim::io {
namespace {

using test::expectInputError;
using test::scratchDir;
using test::writeText;

TEST(Exr, FloatRoundTripIsExactIncludingHighlights) {
  const auto dir = scratchDir();
  ImageF image(7, 5);  // odd sizes catch row-stride mistakes
  for (std::size_t i = 0; i < image.rgb.size(); ++i)
    image.rgb[i] = static_cast<float>(std::pow(1.7, static_cast<double>(i % 23)) * 1e-3 * (1.0 + 0.01 * i));
  image.rgb[5] = 0.0f;
  writeExr(dir / "a.exr", image);
  const ImageF back = readExr(dir / "a.exr");
  EXPECT_EQ(back.width, 7);
  EXPECT_EQ(back.height, 5);
  EXPECT_EQ(back.rgb, image.rgb);  // 32-bit float channels, lossless compression
  EXPECT_GT(*std::max_element(back.rgb.begin(), back.rgb.end()), 100.0f);  // beyond what 8 bits keep
  EXPECT_EQ(std::distance(std::filesystem::directory_iterator(dir), {}), 1);  // no temporaries left
}

TEST(Exr, MissingOrForeignFilesAreInputErrors) {
  const auto dir = scratchDir();
  expectInputError([&] { readExr(dir / "none.exr"); }, {"none.exr", "no such file"});
  writeText(dir / "fake.exr", "not an image");
  expectInputError([&] { readExr(dir / "fake.exr"); }, {"fake.exr"});
}

}  // namespace
}  // namespace msim::io
