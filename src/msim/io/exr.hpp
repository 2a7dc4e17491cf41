#pragma once
// OpenEXR images: linear float RGB for compositing and look development, where the 8-bit PNG's
// tone mapping would throw away the highlights (fire) and the shadows.
#include <filesystem>

#include "msim/io/png.hpp"

namespace msim::io {

// 32-bit float R, G, B channels, ZIP compression; written atomically (temporary name, renamed
// when complete). std::runtime_error naming the file if it cannot be written.
void writeExr(const std::filesystem::path& path, const ImageF& image);

// Reads the R, G, B channels of an EXR file as float (InputError naming the file when it is
// missing, unreadable or has no RGB channels).
ImageF readExr(const std::filesystem::path& path);

}  // namespace msim::io
