#include "msim/render/image_detail.hpp"

#include <cmath>
#include <complex>
#include <numbers>
#include <stdexcept>
#include <string>
#include <vector>

#include "msim/numerics/fft.hpp"

namespace msim::render {

double fineDetailShare(const io::Image& picture, const PixelBox& box) {
  if (box.x0 < 0 || box.y0 < 0 || box.x1 > picture.width || box.y1 > picture.height || box.x0 >= box.x1 ||
      box.y0 >= box.y1)
    throw std::invalid_argument("fineDetailShare: the box " + std::to_string(box.x0) + " " + std::to_string(box.y0) +
                                " " + std::to_string(box.x1) + " " + std::to_string(box.y1) +
                                " is empty or leaves the " + std::to_string(picture.width) + " x " +
                                std::to_string(picture.height) + " picture");
  const int w = box.x1 - box.x0, h = box.y1 - box.y0;
  std::vector<double> luminance(static_cast<std::size_t>(w) * h);
  double mean = 0.0;
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::uint8_t* p = picture.pixel(box.x0 + x, box.y0 + y);
      const double l = (0.2126 * p[0] + 0.7152 * p[1] + 0.0722 * p[2]) / 255.0;
      luminance[static_cast<std::size_t>(y) * w + x] = l;
      mean += l;
    }
  mean /= static_cast<double>(luminance.size());
  const auto hann = [](int i, int n) { return 0.5 - 0.5 * std::cos(2.0 * std::numbers::pi * (i + 0.5) / n); };
  std::vector<std::complex<float>> spectrum(luminance.size());
  for (int y = 0; y < h; ++y)
    for (int x = 0; x < w; ++x) {
      const std::size_t i = static_cast<std::size_t>(y) * w + x;
      spectrum[i] = static_cast<float>((luminance[i] - mean) * hann(x, w) * hann(y, h));
    }
  numerics::FftNd({w, h}).forward(spectrum);
  double upper = 0.0, total = 0.0;
  for (int ky = 0; ky < h; ++ky)
    for (int kx = 0; kx < w; ++kx) {
      if (kx == 0 && ky == 0) continue;
      const double power = std::norm(spectrum[static_cast<std::size_t>(ky) * w + kx]);
      total += power;
      const double fx = double(numerics::signedFrequency(kx, w)) / w, fy = double(numerics::signedFrequency(ky, h)) / h;
      if (std::hypot(fx, fy) > 0.25) upper += power;  // half of the Nyquist frequency 0.5
    }
  return total > 0.0 ? upper / total : 0.0;
}

double fineDetailShare(const io::Image& picture) {
  return fineDetailShare(picture, PixelBox{0, 0, picture.width, picture.height});
}

}  // namespace msim::render
