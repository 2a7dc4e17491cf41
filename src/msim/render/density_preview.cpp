#include "msim/render/density_preview.hpp"

#include <algorithm>
#include <array>
#include <cmath>
#include <optional>

#include "msim/core/parallel.hpp"
#include "msim/render/blackbody.hpp"

namespace msim::render {

namespace {

using Rgb = std::array<float, 3>;
constexpr Rgb kSolidColour = {0.42f, 0.33f, 0.27f};
constexpr float kSolidDepth = 50.0f;  // optical depth of one solid cell: opaque

// Linear radiance per pixel on the grid's own pixel lattice (key light = 1).
struct Radiance {
  int width = 0, height = 0;
  std::vector<Rgb> colour;   // light reaching the camera from gas and solids
  std::vector<float> alpha;  // 1 - transmittance along the view ray
};

inline bool isSolid(const float* solid, std::size_t i) { return solid && solid[i] > 0.5f; }

// Emitted radiance of cell i over a path of `length` metres (zero without an emitter).
template <int D>
class CellEmission {
 public:
  CellEmission(const PreviewEmission<D>& e, const PreviewSettings& s, double length)
      : emitter_(e.emitter ? e.emitter->data().data() : nullptr),
        temperature_(e.temperature ? e.temperature->data().data() : nullptr),
        scale_(static_cast<float>(s.emissionScale * length)) {
    if (emitter_ && temperature_) table_.emplace(s.emissionReference);
  }
  bool active() const { return table_.has_value(); }
  Rgb operator()(std::size_t i) const {
    const float amount = scale_ * std::max(emitter_[i], 0.0f);
    if (!(amount > 0.0f)) return {0, 0, 0};
    const auto c = (*table_)(temperature_[i]);
    return {amount * c[0], amount * c[1], amount * c[2]};
  }

 private:
  const float* emitter_;
  const float* temperature_;
  float scale_;
  std::optional<BlackbodyTable> table_;
};

// 3D: light marches down upAxis accumulating optical depth; the view ray marches along -viewAxis.
Radiance project(const Grid<float, 3>& rho, const float* solid, const PreviewSettings& s,
                 const PreviewEmission<3>& emission) {
  const int view = s.viewAxis, up = s.upAxis;
  int across = 0;
  while (across == view || across == up) ++across;
  const IVec3 n = rho.size();
  const float k = static_cast<float>(s.extinction * rho.spec().dx);

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
      const float cellDepth = isSolid(solid, i) ? kSolidDepth : k * std::max(rho[i], 0.0f);
      lightT[i] = isSolid(solid, i) ? std::exp(-depth) : std::exp(-depth - 0.5f * cellDepth);
      depth += cellDepth;
    }
  }, 64);

  Radiance r;
  r.width = n[across];
  r.height = n[up];
  r.colour.assign(static_cast<std::size_t>(r.width) * r.height, Rgb{0, 0, 0});
  r.alpha.assign(r.colour.size(), 0.0f);
  const float albedo = static_cast<float>(s.albedo), ambient = static_cast<float>(s.ambient);
  const CellEmission<3> emit(emission, s, rho.spec().dx);
  parallelFor(0, r.colour.size(), [&](std::size_t p) {
    IVec3 c;
    c[across] = static_cast<int>(p % r.width);
    c[up] = static_cast<int>(p / r.width);
    float T = 1.0f;
    Rgb L = {0, 0, 0};
    for (int d = n[view] - 1; d >= 0 && T > 1e-4f; --d) {  // front (camera side) to back
      c[view] = d;
      const std::size_t i = rho.index(c);
      if (isSolid(solid, i)) {
        for (int ch = 0; ch < 3; ++ch) L[ch] += T * kSolidColour[ch] * (lightT[i] + ambient);
        T = 0.0f;
        break;
      }
      const float a = 1.0f - std::exp(-k * std::max(rho[i], 0.0f));
      for (int ch = 0; ch < 3; ++ch) L[ch] += T * a * albedo * s.colour[ch] * (lightT[i] + ambient);
      if (emit.active()) {
        const Rgb e = emit(i);
        for (int ch = 0; ch < 3; ++ch) L[ch] += T * e[ch];
      }
      T *= 1.0f - a;
    }
    r.colour[p] = L;
    r.alpha[p] = 1.0f - T;
  }, 256);
  return r;
}

// A 2D field seen face-on, as a slab of thickness depth2D; the light still comes from +y.
Radiance project(const Grid<float, 2>& rho, const float* solid, const PreviewSettings& s,
                 const PreviewEmission<2>& emission) {
  const double dx = rho.spec().dx;
  const double depth = s.depth2D > 0.0 ? s.depth2D : 8.0 * dx;
  const CellEmission<2> emit(emission, s, depth);
  const float kView = static_cast<float>(s.extinction * depth), kLight = static_cast<float>(s.extinction * dx);
  const IVec2 n = rho.size();
  Radiance r;
  r.width = n[0];
  r.height = n[1];
  r.colour.assign(rho.count(), Rgb{0, 0, 0});
  r.alpha.assign(rho.count(), 0.0f);
  const float albedo = static_cast<float>(s.albedo), ambient = static_cast<float>(s.ambient);
  parallelFor(0, static_cast<std::size_t>(n[0]), [&](std::size_t x) {
    float lightDepth = 0.0f;
    for (int y = n[1] - 1; y >= 0; --y) {
      const std::size_t i = rho.index(IVec2(static_cast<int>(x), y));
      if (isSolid(solid, i)) {
        const float lit = std::exp(-lightDepth) + ambient;
        for (int ch = 0; ch < 3; ++ch) r.colour[i][ch] = kSolidColour[ch] * lit;
        r.alpha[i] = 1.0f;
        lightDepth += kSolidDepth;
        continue;
      }
      const float rhoi = std::max(rho[i], 0.0f);
      const float lightT = std::exp(-lightDepth - 0.5f * kLight * rhoi);
      lightDepth += kLight * rhoi;
      const float a = 1.0f - std::exp(-kView * rhoi);
      // Emission through half the slab's smoke, on average.
      const Rgb e = emit.active() ? emit(i) : Rgb{0, 0, 0};
      const float seen = std::exp(-0.5f * kView * rhoi);
      for (int ch = 0; ch < 3; ++ch) r.colour[i][ch] = a * albedo * s.colour[ch] * (lightT + ambient) + seen * e[ch];
      r.alpha[i] = a;
    }
  }, 16);
  return r;
}

// Linear radiance -> 8-bit sRGB through a table: a pow() per channel per pixel would cost more
// than the whole projection.
std::uint8_t toByte(float linear) {
  constexpr int kSteps = 4096;
  static const std::array<std::uint8_t, kSteps + 1> table = [] {
    std::array<std::uint8_t, kSteps + 1> t{};
    for (int i = 0; i <= kSteps; ++i) {
      const double v = static_cast<double>(i) / kSteps;
      const double srgb = v <= 0.0031308 ? 12.92 * v : 1.055 * std::pow(v, 1.0 / 2.4) - 0.055;
      t[i] = static_cast<std::uint8_t>(std::lround(srgb * 255.0));
    }
    return t;
  }();
  return table[static_cast<int>(std::clamp(linear, 0.0f, 1.0f) * kSteps + 0.5f)];
}

}  // namespace

template <int D>
io::Image renderDensityPreview(const Grid<float, D>& density, const PreviewSettings& settings,
                               const Grid<float, D>* solid, const PreviewEmission<D>& emission) {
  const Radiance r = project(density, solid ? solid->data().data() : nullptr, settings, emission);
  const int scale = std::max(1, (settings.minWidth + r.width - 1) / r.width);
  io::Image img(r.width * scale, r.height * scale);
  // Bilinear upscaling of the pixel lattice; the background is a dark blue-grey gradient.
  parallelFor(0, static_cast<std::size_t>(img.height), [&](std::size_t row) {
    const float v = (static_cast<float>(img.height - 1 - row) + 0.5f) / scale - 0.5f;  // lattice y, up
    const int y0 = std::clamp(static_cast<int>(std::floor(v)), 0, r.height - 1);
    const int y1 = std::min(y0 + 1, r.height - 1);
    const float fy = std::clamp(v - y0, 0.0f, 1.0f);
    const Rgb skyTop = {0.05f, 0.06f, 0.09f}, skyBottom = {0.015f, 0.015f, 0.02f};
    const float t = static_cast<float>(row) / std::max(1, img.height - 1);
    for (int col = 0; col < img.width; ++col) {
      const float u = (col + 0.5f) / scale - 0.5f;
      const int x0 = std::clamp(static_cast<int>(std::floor(u)), 0, r.width - 1);
      const int x1 = std::min(x0 + 1, r.width - 1);
      const float fx = std::clamp(u - x0, 0.0f, 1.0f);
      const std::size_t i00 = y0 * r.width + x0, i01 = y0 * r.width + x1, i10 = y1 * r.width + x0,
                        i11 = y1 * r.width + x1;
      const float w00 = (1 - fx) * (1 - fy), w01 = fx * (1 - fy), w10 = (1 - fx) * fy, w11 = fx * fy;
      const float alpha = w00 * r.alpha[i00] + w01 * r.alpha[i01] + w10 * r.alpha[i10] + w11 * r.alpha[i11];
      std::uint8_t* px = img.pixel(col, static_cast<int>(row));
      for (int ch = 0; ch < 3; ++ch) {
        const float L = w00 * r.colour[i00][ch] + w01 * r.colour[i01][ch] + w10 * r.colour[i10][ch] +
                        w11 * r.colour[i11][ch];
        const float background = skyTop[ch] * (1 - t) + skyBottom[ch] * t;
        px[ch] = toByte(L + (1.0f - alpha) * background);
      }
    }
  }, 8);
  return img;
}

template io::Image renderDensityPreview<2>(const Grid<float, 2>&, const PreviewSettings&, const Grid<float, 2>*,
                                           const PreviewEmission<2>&);
template io::Image renderDensityPreview<3>(const Grid<float, 3>&, const PreviewSettings&, const Grid<float, 3>*,
                                           const PreviewEmission<3>&);

}  // namespace msim::render
