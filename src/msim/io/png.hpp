#pragma once
// 8-bit RGB images and PNG files (libpng). ImageF holds linear float radiance as renderers
// produce it; toImage8() applies display gamma and clamps to [0, 1] before quantising.
#include <cstdint>
#include <filesystem>
#include <vector>

namespace msim::io {

struct Image {
  int width = 0;
  int height = 0;
  std::vector<std::uint8_t> rgb;  // row-major from the top row, 3 bytes per pixel

  Image() = default;
  Image(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, 0) {}
  std::uint8_t* pixel(int x, int y) { return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3; }
  const std::uint8_t* pixel(int x, int y) const { return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3; }
};

struct ImageF {
  int width = 0;
  int height = 0;
  std::vector<float> rgb;  // linear values, row-major from the top row, 3 floats per pixel

  ImageF() = default;
  ImageF(int w, int h) : width(w), height(h), rgb(static_cast<std::size_t>(w) * h * 3, 0.0f) {}
  float* pixel(int x, int y) { return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3; }
  const float* pixel(int x, int y) const { return rgb.data() + (static_cast<std::size_t>(y) * width + x) * 3; }

  // Each channel: round(255 * clamp(v, 0, 1)^(1/gamma)); NaN becomes 0. gamma = 1 is linear.
  Image toImage8(double gamma = 2.2) const;
};

// Writes an 8-bit RGB PNG atomically. std::invalid_argument if the pixel buffer does not match
// width*height*3 or a dimension is not positive; std::runtime_error if writing fails.
void writePng(const std::filesystem::path& path, const Image& image);

// Reads any PNG (gray, palette, alpha, 16-bit are converted; alpha is composited over black) into
// 8-bit RGB. InputError naming the file for a missing or invalid file.
Image readPng(const std::filesystem::path& path);

}  // namespace msim::io
