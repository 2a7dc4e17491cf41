#include "msim/io/png.hpp"

#include <png.h>

#include <algorithm>
#include <cmath>
#include <cstring>
#include <stdexcept>
#include <string>

#include "msim/core/error.hpp"
#include "msim/io/atomic_file.hpp"

namespace msim::io {

Image ImageF::toImage8(double gamma) const {
  Image out(width, height);
  const float invGamma = static_cast<float>(1.0 / gamma);
  for (std::size_t i = 0; i < rgb.size(); ++i) {
    const float v = rgb[i];
    // std::clamp passes NaN through, so test it explicitly rather than rely on a comparison order.
    const float c = std::isnan(v) ? 0.0f : std::clamp(v, 0.0f, 1.0f);
    out.rgb[i] = static_cast<std::uint8_t>(std::lround(255.0f * std::pow(c, invGamma)));
  }
  return out;
}

void writePng(const std::filesystem::path& path, const Image& image) {
  if (image.width <= 0 || image.height <= 0 ||
      image.rgb.size() != static_cast<std::size_t>(image.width) * image.height * 3)
    throw std::invalid_argument("writePng: image " + std::to_string(image.width) + "x" + std::to_string(image.height) +
                                " with " + std::to_string(image.rgb.size()) + " bytes for " + path.string());
  writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
    png_image png;
    std::memset(&png, 0, sizeof png);
    png.version = PNG_IMAGE_VERSION;
    png.width = static_cast<png_uint_32>(image.width);
    png.height = static_cast<png_uint_32>(image.height);
    png.format = PNG_FORMAT_RGB;
    const bool ok = png_image_write_to_file(&png, tmp.c_str(), 0, image.rgb.data(), 0, nullptr) != 0;
    const std::string message = png.message;
    png_image_free(&png);
    if (!ok) throw std::runtime_error("cannot write PNG " + path.string() + ": " + message);
  });
}

Image readPng(const std::filesystem::path& path) {
  png_image png;
  std::memset(&png, 0, sizeof png);
  png.version = PNG_IMAGE_VERSION;
  if (!png_image_begin_read_from_file(&png, path.c_str())) {
    const std::string message = png.message;
    png_image_free(&png);
    throw InputError(path.string() + ": cannot read PNG image (" + message + ")");
  }
  png.format = PNG_FORMAT_RGB;
  Image image(static_cast<int>(png.width), static_cast<int>(png.height));
  const png_color black{0, 0, 0};
  if (!png_image_finish_read(&png, &black, image.rgb.data(), 0, nullptr)) {
    const std::string message = png.message;
    png_image_free(&png);
    throw InputError(path.string() + ": corrupt PNG image (" + message + ")");
  }
  return image;
}

}  // namespace msim::io
