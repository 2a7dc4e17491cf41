#include "msim/render/blobs.hpp"

#include <algorithm>
#include <chrono>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include "msim/core/parallel.hpp"
#include "msim/core/seconds_since.hpp"
#include "msim/render/phase_function.hpp"

namespace msim::render {

namespace {

constexpr double kInv4Pi = 0.25 * std::numbers::inv_pi;

bool finite(const Vec3& v) { return v.allFinite(); }

// 2D Gaussian of the closest approach: the whole-line integral of G_sigma at distance^2 d2 (eq. 5.17).
double closestApproachGaussian(double d2, double sigma) {
  return std::exp(-d2 / (2.0 * sigma * sigma)) / (2.0 * std::numbers::pi * sigma * sigma);
}

// m g2(d) (1/2) [erf((b - c) / (sqrt2 sigma)) - erf((a - c) / (sqrt2 sigma))] given c and d^2.
double chordIntegral(double mass, double sigma, double c, double d2, double a, double b) {
  const double k = 1.0 / (std::numbers::sqrt2 * sigma);
  return mass * closestApproachGaussian(d2, sigma) * 0.5 * (std::erf((b - c) * k) - std::erf((a - c) * k));
}

}  // namespace

double gaussianKernel(double r, double sigma) {
  if (!(sigma > 0.0) || !std::isfinite(sigma))
    throw std::invalid_argument("gaussianKernel: sigma must be positive and finite, got " + std::to_string(sigma));
  return std::exp(-r * r / (2.0 * sigma * sigma)) / (std::pow(2.0 * std::numbers::pi, 1.5) * sigma * sigma * sigma);
}

double blobLineIntegral(const Blob& blob, const Ray& ray, double a, double b) {
  if (std::isnan(a) || std::isnan(b) || a > b)
    throw std::invalid_argument("blobLineIntegral: need a <= b, got a = " + std::to_string(a) + ", b = " + std::to_string(b));
  const Vec3 v = blob.centre - ray.origin;
  const double c = v.dot(ray.direction);
  return chordIntegral(blob.mass, blob.width, c, std::max(0.0, v.squaredNorm() - c * c), a, b);
}

BlobSet::BlobSet(std::vector<Blob> blobs) : blobs_(std::move(blobs)) {
  for (std::size_t k = 0; k < blobs_.size(); ++k) {
    const Blob& b = blobs_[k];
    const std::string name = "blob " + std::to_string(k);
    if (!finite(b.centre)) throw std::invalid_argument(name + ": centre must be finite");
    if (!std::isfinite(b.mass) || b.mass < 0.0)
      throw std::invalid_argument(name + ": mass must be finite and >= 0, got " + std::to_string(b.mass));
    if (!std::isfinite(b.width) || !(b.width > 0.0))
      throw std::invalid_argument(name + ": width (sigma) must be finite and positive, got " + std::to_string(b.width));
    if (!finite(b.emission) || (b.emission.array() < 0.0).any())
      throw std::invalid_argument(name + ": emission must be finite and >= 0");
  }
}

double BlobSet::totalMass() const {
  double m = 0.0;
  for (const Blob& b : blobs_) m += b.mass;
  return m;
}

double BlobSet::density(const Vec3& x) const {
  double rho = 0.0;
  for (const Blob& b : blobs_) rho += b.mass * gaussianKernel((x - b.centre).norm(), b.width);
  return rho;
}

double BlobSet::opticalDepth(const Ray& ray, double a, double b) const {
  double g = 0.0;
  for (const Blob& blob : blobs_) g += blobLineIntegral(blob, ray, a, b);
  return g;
}

void BlobRenderSettings::validate() const {
  if (!(cutoffWidths >= 1.0 && cutoffWidths <= 10.0))
    throw std::invalid_argument("blob render settings: cutoffWidths must be in [1, 10], got " + std::to_string(cutoffWidths));
  if (tileSize < 1) throw std::invalid_argument("blob render settings: tileSize must be >= 1, got " + std::to_string(tileSize));
}

namespace {

// What the shooting pass leaves on a blob for the camera rays: J_k(s) = base + sum_l
// lit[l] p(toLight[l] . s) / (4 pi), s the camera ray's direction (the cosine between the light's
// and the scattered light's directions of travel, as in renderVolume).
struct BlobSource {
  Vec3 base;                  // Omega I_sky + (1 - Omega) Q_k
  std::vector<Vec3> lit;      // Omega E_l T_lk per light
  std::vector<Vec3> toLight;  // unit, from the centre towards each light
};

// Optical depth from blob k's centre towards a light (T14's shadow ray between element centres).
double shadowDepth(const std::vector<Blob>& blobs, std::size_t k, const Ray& ray, double distance, double cutoff,
                   bool selfShadowing) {
  double depth = 0.0;
  for (std::size_t j = 0; j < blobs.size(); ++j) {
    if (j == k) continue;
    const Blob& b = blobs[j];
    const Vec3 v = b.centre - ray.origin;
    const double c = v.dot(ray.direction), R = cutoff * b.width;
    if (c + R < 0.0 || c - R > distance) continue;
    const double d2 = std::max(0.0, v.squaredNorm() - c * c);
    if (d2 >= R * R) continue;
    depth += chordIntegral(b.mass, b.width, c, d2, 0.0, distance);
  }
  if (selfShadowing) depth += blobs[k].mass / (8.0 * std::numbers::pi * blobs[k].width * blobs[k].width);
  return depth;
}

// Indices of chords ordered by key(chord) by insertion sort: O(n) for the nearly sorted lists the
// depth-sorted tile lists give (neighbouring rays meet the blobs in almost the same order).
template <typename Key>
void insertionSort(std::vector<std::size_t>& idx, Key&& key) {
  for (std::size_t i = 1; i < idx.size(); ++i) {
    const std::size_t v = idx[i];
    const double kv = key(v);
    std::size_t j = i;
    for (; j > 0 && key(idx[j - 1]) > kv; --j) idx[j] = idx[j - 1];
    idx[j] = v;
  }
}

}  // namespace

BlobRenderResult renderBlobs(const BlobSet& blobSet, const Camera& camera, const std::vector<Light>& lights,
                             const Medium& medium, const VolumeRenderSettings& settings,
                             const BlobRenderSettings& blobSettings, const BlobPixelShader& shade) {
  medium.validate();
  settings.validate();
  blobSettings.validate();
  for (const Light& l : lights) l.validate();
  const CameraRays rays(camera);
  const std::vector<Blob>& blobs = blobSet.blobs();
  const std::size_t n = blobs.size();
  const double sigmaT = medium.extinction, omega = medium.albedo, cutoff = blobSettings.cutoffWidths;
  BlobRenderResult result;

  // Shooting pass: lights -> blobs (T14), one shadow ray per blob and light.
  auto t0 = std::chrono::steady_clock::now();
  std::vector<BlobSource> sources(n);
  parallelFor(0, n, [&](std::size_t k) {
    const Blob& b = blobs[k];
    BlobSource& s = sources[k];
    s.base = omega * settings.ambient + (1.0 - omega) * b.emission;
    for (const Light& light : lights) {
      const LightSample ls = illuminate(light, b.centre, b.width);
      const double depth = shadowDepth(blobs, k, Ray{b.centre, ls.toLight}, ls.distance, cutoff, blobSettings.selfShadowing);
      s.lit.push_back(omega * std::exp(-sigmaT * depth) * ls.irradiance);
      s.toLight.push_back(ls.toLight);
    }
  }, 16);
  result.stats.secondsShadows = secondsSince(t0);

  // Tile lists: a blob goes to every tile its cut-off sphere's screen box touches. The box is that
  // of the 8 projected corners of the cube around the sphere in the camera's basis (the cube's
  // projection is the hull of its corners' when all lie in front); otherwise every tile.
  t0 = std::chrono::steady_clock::now();
  const int tile = blobSettings.tileSize;
  const int tilesX = (camera.width + tile - 1) / tile, tilesY = (camera.height + tile - 1) / tile;
  std::vector<std::vector<std::size_t>> tileBlobs(static_cast<std::size_t>(tilesX) * tilesY);
  for (std::size_t k = 0; k < n; ++k) {
    if (blobs[k].mass == 0.0) continue;
    const double R = cutoff * blobs[k].width;
    double x0 = std::numeric_limits<double>::infinity(), y0 = x0, x1 = -x0, y1 = -x0;
    bool all = false;
    for (int corner = 0; corner < 8 && !all; ++corner) {
      const Vec3 p = blobs[k].centre + R * ((corner & 1 ? 1.0 : -1.0) * rays.right() + (corner & 2 ? 1.0 : -1.0) * rays.up() +
                                            (corner & 4 ? 1.0 : -1.0) * rays.forward());
      const auto q = rays.project(p);
      if (!q) {
        all = true;
        break;
      }
      x0 = std::min(x0, q->x()), x1 = std::max(x1, q->x()), y0 = std::min(y0, q->y()), y1 = std::max(y1, q->y());
    }
    if (!all && (x1 < 0.0 || y1 < 0.0 || x0 > camera.width || y0 > camera.height)) continue;
    const int tx0 = all ? 0 : std::clamp(static_cast<int>(std::floor(x0 / tile)), 0, tilesX - 1);
    const int tx1 = all ? tilesX - 1 : std::clamp(static_cast<int>(std::floor(x1 / tile)), 0, tilesX - 1);
    const int ty0 = all ? 0 : std::clamp(static_cast<int>(std::floor(y0 / tile)), 0, tilesY - 1);
    const int ty1 = all ? tilesY - 1 : std::clamp(static_cast<int>(std::floor(y1 / tile)), 0, tilesY - 1);
    for (int ty = ty0; ty <= ty1; ++ty)
      for (int tx = tx0; tx <= tx1; ++tx) tileBlobs[static_cast<std::size_t>(ty) * tilesX + tx].push_back(k);
  }

  // Front to back by the near side of the cut-off sphere, so each ray's chords come nearly sorted.
  parallelFor(0, tileBlobs.size(), [&](std::size_t t) {
    std::sort(tileBlobs[t].begin(), tileBlobs[t].end(), [&](std::size_t a, std::size_t b) {
      return (blobs[a].centre - camera.position).norm() - cutoff * blobs[a].width <
             (blobs[b].centre - camera.position).norm() - cutoff * blobs[b].width;
    });
  }, 1);

  // Camera rays, App. 5.C sweep per ray, tiles in parallel.
  const HenyeyGreenstein phase(medium.phaseG);
  result.radiance = FloatImage(camera.width, camera.height);
  std::vector<long long> pairsPerTile(tileBlobs.size(), 0);
  parallelFor(0, tileBlobs.size(), [&](std::size_t t) {
    const int tx = static_cast<int>(t % tilesX), ty = static_cast<int>(t / tilesX);
    std::vector<BlobChord> chords;
    std::vector<std::size_t> ins, outs;  // chords by entry and by exit
    std::vector<Vec3> chordSource;       // gamma_k J_k(s) of each chord
    std::vector<double> lightPhase(lights.size());
    for (int py = ty * tile; py < std::min(camera.height, (ty + 1) * tile); ++py)
      for (int px = tx * tile; px < std::min(camera.width, (tx + 1) * tile); ++px) {
        const Ray ray = rays.ray(px + 0.5, py + 0.5);
        chords.clear();
        ins.clear();
        outs.clear();
        chordSource.clear();
        // A directional light has one scattering angle per ray; the others' vary from blob to blob.
        for (std::size_t l = 0; l < lights.size(); ++l)
          if (lights[l].type == Light::Type::Directional)
            lightPhase[l] = phase(-lights[l].direction.normalized().dot(ray.direction)) * kInv4Pi;
        for (std::size_t k : tileBlobs[t]) {
          const Blob& b = blobs[k];
          const Vec3 v = b.centre - ray.origin;
          const double c = v.dot(ray.direction), R = cutoff * b.width;
          const double d2 = std::max(0.0, v.squaredNorm() - c * c);
          if (d2 >= R * R) continue;
          const double h = std::sqrt(R * R - d2), in = std::max(0.0, c - h), out = c + h;
          if (!(out > in)) continue;  // behind the camera
          // A whole chord is symmetric about c: one erf, m g2(d) erf(h / (sqrt2 sigma)).
          const double depth = in > 0.0 ? b.mass * closestApproachGaussian(d2, b.width) *
                                               std::erf(h / (std::numbers::sqrt2 * b.width))
                                         : chordIntegral(b.mass, b.width, c, d2, in, out);
          chords.push_back({in, out, depth, depth / (out - in), k});
        }
        pairsPerTile[t] += static_cast<long long>(chords.size());
        for (std::size_t i = 0; i < chords.size(); ++i) {
          const BlobSource& s = sources[chords[i].blob];
          Vec3 J = s.base;
          for (std::size_t l = 0; l < s.lit.size(); ++l)
            J += s.lit[l] * (lights[l].type == Light::Type::Directional ? lightPhase[l]
                                                                        : phase(s.toLight[l].dot(ray.direction)) * kInv4Pi);
          chordSource.push_back(chords[i].gamma * J);
          ins.push_back(i);
          outs.push_back(i);
        }
        insertionSort(ins, [&](std::size_t i) { return chords[i].in; });
        insertionSort(outs, [&](std::size_t i) { return chords[i].out; });

        Vec3 radiance = Vec3::Zero(), source = Vec3::Zero();
        double T = 1.0, gamma = 0.0, u = 0.0, opacity = 0.0;
        int active = 0;
        // Merge of the entries and exits (an entry first on a tie: a chord ends after it begins).
        for (std::size_t nextIn = 0, nextOut = 0; nextOut < outs.size();) {
          const bool enter = nextIn < ins.size() && chords[ins[nextIn]].in <= chords[outs[nextOut]].out;
          const std::size_t chord = enter ? ins[nextIn++] : outs[nextOut++];
          const double eu = enter ? chords[chord].in : chords[chord].out;
          const double len = eu - u;
          if (active > 0 && len > 0.0 && gamma > 0.0) {
            const double tau = std::exp(-sigmaT * gamma * len);
            radiance += (T * (1.0 - tau) / gamma) * source;  // (1 - tau_j) J_j, J_j = source / gamma
            opacity += T * (1.0 - tau);
            T *= tau;
            if (T < kBlobMinTransmittance) break;
          }
          u = eu;
          const double sign = enter ? 1.0 : -1.0;
          active += enter ? 1 : -1;
          gamma += sign * chords[chord].gamma;
          source += sign * chordSource[chord];
          if (active == 0 || gamma < 0.0) {  // round-off of the add / remove sweep (App. 5.C)
            gamma = 0.0;
            source.setZero();
          }
          source = source.cwiseMax(0.0);
        }
        if (shade)
          radiance = shade(px, py, ray, chords, BlobRayIntegral{radiance, opacity});
        else if (T >= kBlobMinTransmittance)
          radiance += T * settings.background;
        float* out = result.radiance.pixel(px, py);
        for (int ch = 0; ch < 3; ++ch) out[ch] = static_cast<float>(radiance[ch]);
      }
  }, 1);
  result.stats.secondsRays = secondsSince(t0);
  result.stats.rays = static_cast<long long>(camera.width) * camera.height;
  for (long long p : pairsPerTile) result.stats.blobRayPairs += p;

  FloatImage display = result.radiance;
  for (float& v : display.rgb) {
    const float x = static_cast<float>(settings.exposure) * v;
    v = settings.toneMap ? x / (1.0f + x) : x;
  }
  result.image = display.toImage8(settings.gamma);
  return result;
}

}  // namespace msim::render
