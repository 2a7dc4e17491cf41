#include "msim/io/exr.hpp"

#include <exception>

#include <ImfChannelList.h>
#include <ImfFrameBuffer.h>
#include <ImfHeader.h>
#include <ImfInputFile.h>
#include <ImfOutputFile.h>

#include "msim/core/error.hpp"
#include "msim/io/atomic_file.hpp"

namespace msim::io {

namespace {

// The three interleaved channels of an RGB float buffer as OpenEXR slices.
Imf::FrameBuffer slices(float* rgb, int width) {
  const std::size_t pixel = 3 * sizeof(float), row = pixel * static_cast<std::size_t>(width);
  Imf::FrameBuffer fb;
  const char* names[] = {"R", "G", "B"};
  for (int c = 0; c < 3; ++c)
    fb.insert(names[c], Imf::Slice(Imf::FLOAT, reinterpret_cast<char*>(rgb + c), pixel, row));
  return fb;
}

}  // namespace

void writeExr(const std::filesystem::path& path, const ImageF& image) {
  writeFileAtomically(path, [&](const std::filesystem::path& tmp) {
    Imf::Header header(image.width, image.height);
    header.compression() = Imf::ZIP_COMPRESSION;
    for (const char* c : {"R", "G", "B"}) header.channels().insert(c, Imf::Channel(Imf::FLOAT));
    try {
      Imf::OutputFile file(tmp.c_str(), header);
      // OpenEXR only reads through the frame buffer; the cast does not let it write.
      file.setFrameBuffer(slices(const_cast<float*>(image.rgb.data()), image.width));
      file.writePixels(image.height);
    } catch (const std::exception& e) {
      throw std::runtime_error("cannot write " + path.string() + ": " + e.what());
    }
  });
}

ImageF readExr(const std::filesystem::path& path) {
  if (!std::filesystem::exists(path)) throw InputError(path.string() + ": no such file");
  try {
    Imf::InputFile file(path.c_str());
    const Imath::Box2i window = file.header().dataWindow();
    const auto& channels = file.header().channels();
    for (const char* c : {"R", "G", "B"})
      if (!channels.findChannel(c)) throw InputError(path.string() + ": the EXR file has no '" + c + "' channel");
    ImageF image(window.max.x - window.min.x + 1, window.max.y - window.min.y + 1);
    // Slices are addressed by absolute pixel coordinates: shift the base by the window origin.
    float* base = image.rgb.data() - 3 * (static_cast<std::ptrdiff_t>(window.min.y) * image.width + window.min.x);
    file.setFrameBuffer(slices(base, image.width));
    file.readPixels(window.min.y, window.max.y);
    return image;
  } catch (const InputError&) {
    throw;
  } catch (const std::exception& e) {
    throw InputError(path.string() + ": cannot read the EXR file (" + e.what() + ")");
  }
}

}  // namespace msim::io
