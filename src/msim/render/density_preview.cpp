#include "msim/render/density_preview.hpp"

#include <algorithm>
#include <cmath>

#include "msim/core/parallel.hpp"

namespace msim::render {

namespace {

// Radiance per pixel (linear, key light = 1) on the grid's own pixel lattice.
struct Radiance {
  int width = 0, height = 0;
  std::vector<float> value;  // grey level: scattered light
  std::vector<float> alpha;  // 1 - transmittance along the view ray
};

// 3D: light marches down upAxis accumulating optical depth; the view ray marches along -viewAxis.
Radiance project(const Grid<float, 3>& rho, const PreviewSettings& s) {
  const int view = s.viewAxis, up = s.upAxis;
  int across = 0;
  while (across == view || across == up) ++across;
  const IVec3 n = rho.size();
  const double dx = rho.spec().dx;
  const float k = static_cast<float>(s.extinction * dx);

  // Transmittance of the key light reaching each voxel (light enters from the top of upAxis).
  std::vector<float> lightT(rho.count());
  parallelFor(0, static_cast<std::size_t>(n[across]) * n[view], [&](std::size_t column) {
    IVec3 c;
    c[across] = static_cast<int>(column % n[across]);
    c[view] = static_cast<int>(column / n[across]);
    float depth = 0.0f;
    for (int j = n[up] - 1; j >= 0; --j) {
      c[up] = j;
      const std::size_t i = rho.index(c);
      lightT[i] = std::exp(-depth - 0.5f * k * rho[i]);
      depth += k * rho[i];
    }
  }, 64);

  Radiance r;
  r.width = n[across];
  r.height = n[up];
  r.value.assign(static_cast<std::size_t>(r.width) * r.height, 0.0f);
  r.alpha.assign(r.value.size(), 0.0f);
  const float albedo = static_cast<float>(s.albedo), ambient = static_cast<float>(s.ambient);
  parallelFor(0, r.value.size(), [&](std::size_t p) {
    IVec3 c;
    c[across] = static_cast<int>(p % r.width);
    c[up] = static_cast<int>(p / r.width);
    float T = 1.0f, L = 0.0f;
    for (int d = n[view] - 1; d >= 0; --d) {  // front (camera side) to back
      c[view] = d;
      const std::size_t i = rho.index(c);
      const float a = 1.0f - std::exp(-k * std::max(rho[i], 0.0f));
      L += T * a * albedo * (lightT[i] + ambient);
      T *= 1.0f - a;
      if (T < 1e-4f) break;
    }
    r.value[p] = L;
    r.alpha[p] = 1.0f - T;
  }, 256);
  return r;
}

Radiance project(const Grid<float, 2>& rho, const PreviewSettings& s) {
  // A 2D field seen face-on, as a slab of thickness depth2D; the light still comes from +y.
  const double dx = rho.spec().dx;
  const double depth = s.depth2D > 0.0 ? s.depth2D : 8.0 * dx;
  const float kView = static_cast<float>(s.extinction * depth), kLight = static_cast<float>(s.extinction * dx);
  const IVec2 n = rho.size();
  Radiance r;
  r.width = n[0];
  r.height = n[1];
  r.value.assign(rho.count(), 0.0f);
  r.alpha.assign(rho.count(), 0.0f);
  const float albedo = static_cast<float>(s.albedo), ambient = static_cast<float>(s.ambient);
  parallelFor(0, static_cast<std::size_t>(n[0]), [&](std::size_t x) {
    float lightDepth = 0.0f;
    for (int y = n[1] - 1; y >= 0; --y) {
      const std::size_t i = rho.index(IVec2(static_cast<int>(x), y));
      const float rhoi = std::max(rho[i], 0.0f);
      const float lightT = std::exp(-lightDepth - 0.5f * kLight * rhoi);
      lightDepth += kLight * rhoi;
      const float a = 1.0f - std::exp(-kView * rhoi);
      r.value[i] = a * albedo * (lightT + ambient);
      r.alpha[i] = a;
    }
  }, 16);
  return r;
}

std::uint8_t toByte(float linear) {
  const float srgb = linear <= 0.0031308f ? 12.92f * linear : 1.055f * std::pow(linear, 1.0f / 2.4f) - 0.055f;
  return static_cast<std::uint8_t>(std::lround(std::clamp(srgb, 0.0f, 1.0f) * 255.0f));
}

}  // namespace

template <int D>
io::Image renderDensityPreview(const Grid<float, D>& density, const PreviewSettings& settings) {
  const Radiance r = project(density, settings);
  const int scale = std::max(1, (settings.minWidth + r.width - 1) / r.width);
  io::Image img(r.width * scale, r.height * scale);
  // Bilinear upscaling of the pixel lattice; the background is a dark blue-grey gradient.
  parallelFor(0, static_cast<std::size_t>(img.height), [&](std::size_t row) {
    const float v = (static_cast<float>(img.height - 1 - row) + 0.5f) / scale - 0.5f;  // lattice y, up
    const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, r.height - 1);
    const int y1 = std::min(y0 + 1, r.height - 1);
    const float fy = std::clamp(v - y0, 0.0f, 1.0f);
    const float skyTop[3] = {0.05f, 0.06f, 0.09f}, skyBottom[3] = {0.015f, 0.015f, 0.02f};
    const float t = static_cast<float>(row) / std::max(1, img.height - 1);
    for (int col = 0; col < img.width; ++col) {
      const float u = (col + 0.5f) / scale - 0.5f;
      const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, r.width - 1);
      const int x1 = std::min(x0 + 1, r.width - 1);
      const float fx = std::clamp(u - x0, 0.0f, 1.0f);
      auto lerp2 = [&](const std::vector<float>& f) {
        const float a = f[y0 * r.width + x0] * (1 - fx) + f[y0 * r.width + x1] * fx;
        const float b = f[y1 * r.width + x0] * (1 - fx) + f[y1 * r.width + x1] * fx;
        return a * (1 - fy) + b * fy;
      };
      const float L = lerp2(r.value), alpha = lerp2(r.alpha);
      std::uint8_t* px = &img.rgb[(row * img.width + col) * 3];
      for (int ch = 0; ch < 3; ++ch) {
        const float background = skyTop[ch] * (1 - t) + skyBottom[ch] * t;
        px[ch] = toByte(L + (1.0f - alpha) * background);
      }
    }
  }, 8);
  return img;
}

template io::Image renderDensityPreview<2>(const Grid<float, 2>&, const PreviewSettings&);
template io::Image renderDensityPreview<3>(const Grid<float, 3>&, const PreviewSettings&);

}  // namespace msim::render
