#pragma once
// Blobs: a density field as a sum of Gaussian smoothing kernels, and its rendering by blob ray
// integration (Stam ch. 4.1-4.2 and 5.3-5.4, App. 5.C; seed notes T7, T8, T13, T14, T21).
//
// Kernel (eq. 4.2, T7): G_sigma(r) = (2 pi)^(-3/2) sigma^-3 exp(-r^2 / (2 sigma^2)), normalised so
// that its integral over space is 1; a blob k of mass m_k and width sigma_k adds m_k G_sigma_k(x -
// x_k) to the density (eq. 4.7, T8): rho(x) = sum_k m_k G_sigma_k(x - x_k), total mass sum_k m_k.
//
// Line integrals (eq. 5.17, T13): along the ray x_u = o + u s, with c_k = (x_k - o) . s the
// parameter of closest approach and d_k the distance there, |x_u - x_k|^2 = d_k^2 + (u - c_k)^2
// separates, so
//   integral_a^b m_k G dx_u = m_k g2(d_k) (1/2) [erf((b - c_k) / (sqrt2 sigma)) - erf((a - c_k) / (sqrt2 sigma))],
//   g2(d) = exp(-d^2 / (2 sigma^2)) / (2 pi sigma^2)   (the 2D Gaussian of the closest approach).
// (The seed prints the prefactor as 1/(4 pi sigma^2) times the erf difference, the same thing.)
// Over the whole line the integral is m_k g2(d_k).
#include <functional>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/io/png.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/light.hpp"
#include "msim/render/volume_renderer.hpp"

namespace msim::render {

struct Blob {
  Vec3 centre = Vec3::Zero();     // x_k [m]
  double mass = 1.0;              // m_k [kg], >= 0
  double width = 0.1;             // sigma_k [m], > 0: the Gaussian's standard deviation
  Vec3 emission = Vec3::Zero();   // Q_k: emitted radiance per channel (the (1 - Omega) Q term of eq. 5.9), >= 0
};

// G_sigma(r) of eq. 4.2 (std::invalid_argument for sigma <= 0).
double gaussianKernel(double r, double sigma);

// integral_a^b m G_sigma(x_u - x_k) du along the ray (eq. 5.17, closed form above), a <= b; a and b
// may be infinite. The ray's direction must be unit length.
double blobLineIntegral(const Blob& blob, const Ray& ray, double a, double b);

class BlobSet {
 public:
  // std::invalid_argument naming the blob: negative mass, width not positive, negative emission,
  // or anything non-finite.
  explicit BlobSet(std::vector<Blob> blobs);

  const std::vector<Blob>& blobs() const { return blobs_; }
  std::size_t size() const { return blobs_.size(); }
  double totalMass() const;

  // rho(x) of eq. 4.7, every blob untruncated.
  double density(const Vec3& x) const;
  // integral_a^b rho(x_u) du: the optical depth per unit extinction, sum of eq. 5.17 over the blobs.
  double opticalDepth(const Ray& ray, double a, double b) const;

 private:
  std::vector<Blob> blobs_;
};

struct BlobRenderSettings {
  // Blobs are cut off at cutoffWidths * sigma for the ray lists (bounding spheres, T8/T13): a ray
  // passing farther from a centre misses it, a ray through it integrates the chord inside the
  // sphere exactly. 4 sigma leaves out 0.1% of a blob's mass (3D Gaussian) and 3.4e-4 of the peak
  // line integral at the rim.
  double cutoffWidths = 4.0;
  // Add each blob's shadow on itself to its light transmittance (see renderBlobs); off, only the
  // other blobs shadow it, as in Stam's shooting between blob centres (T14).
  bool selfShadowing = true;
  int tileSize = 16;  // pixels per side of the tiles whose blob lists are built by bounding-box culling

  // std::invalid_argument for cutoffWidths not in [1, 10] or tileSize < 1.
  void validate() const;
};

struct BlobRenderStats {
  long long rays = 0;
  long long blobRayPairs = 0;  // blob chords integrated by the camera rays
  double secondsShadows = 0.0, secondsRays = 0.0;
};

struct BlobRenderResult {
  FloatImage radiance;  // before exposure and tone mapping
  io::Image image;      // exposure, tone map, gamma, 8 bits (as renderVolume)
  BlobRenderStats stats;
};

// A camera ray's chord through blob k's cut-off sphere, [in, out] along the ray (clipped at the
// camera), with its exact integral depth = integral_in^out m_k G du (eq. 5.17).
struct BlobChord {
  double in = 0.0, out = 0.0;
  double depth = 0.0;
  double gamma = 0.0;  // depth / (out - in): the blob's depth per unit length spread over its chord
  std::size_t blob = 0;
};

// renderBlobs stops a ray once its transmittance T falls below this and adds no background behind
// it (as renderVolume: the rest of the ray adds < 1e-4 of J).
inline constexpr double kBlobMinTransmittance = 1e-4;

// What the ray integration of renderBlobs found along one camera ray (up to where it stopped).
struct BlobRayIntegral {
  Vec3 scattered = Vec3::Zero();  // I_d = sum_j T_j (1 - tau_j) J_j, the light the blobs send along the ray
  double opacity = 0.0;           // sum_j T_j (1 - tau_j) = 1 - T, summed as I_d is
};

// Radiance of pixel (px, py) from its ray, its chords (in no particular order) and their integral.
using BlobPixelShader = std::function<Vec3(int px, int py, const Ray& ray, std::span<const BlobChord> chords,
                                           const BlobRayIntegral& integral)>;

// Renders a blob set with lights, sky light and per-blob emission (Stam's "high quality, level 1",
// T21: one shooting pass lights -> blobs, then ray integration of T13):
//  - Shooting (T14): each blob gets the source J_k(s) = Omega [ sum_l E_l T_lk p(s_l . s) / (4 pi)
//    + I_sky ] + (1 - Omega) Q_k, with E_l the unshadowed irradiance at the centre (light.hpp), p
//    the Henyey-Greenstein phase function (normalised to 4 pi, as in volume_renderer.hpp), I_sky =
//    settings.ambient (unshadowed) and T_lk = exp(-sigma_t Gamma_lk) the transparency along one ray
//    from the blob's centre to the light (eq. 5.17, exact, through every other blob whose cut-off
//    sphere the ray crosses; up to the light's distance for point and spot lights). With selfShadowing, Gamma_lk also holds the blob's
//    own mass-averaged depth towards the light, m_k / (8 pi sigma_k^2): for a point of the blob at
//    offset z along the light and r across it the depth to the light through the blob is m_k g2(r)
//    Phi(-z / sigma), and averaging over the blob's own Gaussian gives E[g2(r)] E[Phi] = (1 / (4 pi
//    sigma^2)) (1/2). Stam's centre-to-centre shooting leaves a blob's shadow on itself out, which
//    makes a lone thick blob as bright as a thin one.
//  - Ray integration (App. 5.C, T13): each camera ray lists the blobs whose cut-off spheres it
//    crosses (tile lists, then the exact distance), with the chord [u_in, u_out] (clipped at the
//    camera). The 2|L| chord ends sorted front to back make the intervals of eq. 5.19; over its
//    chord a blob's optical depth is spread evenly, gamma_k = Gamma_k / (u_out - u_in), with
//    Gamma_k its exact chord integral (eq. 5.17) - the seed's recommended normalisation of eq. 5.18,
//    so the ray's total transparency exp(-sigma_t sum_k Gamma_k) is exact. Sweeping the sorted
//    ends adds and removes gamma_k and gamma_k J_k(s); each interval integrates exactly with its
//    constant density and density-weighted source J_j: I_d += T (1 - tau_j) J_j, T *= tau_j, tau_j =
//    exp(-sigma_t gamma (u_{j+1} - u_j)). The sums are clamped at 0 against the round-off of the
//    add / remove sweep (App. 5.C); rays stop once T < 1e-4. Samples sit where the blobs are, so a
//    blob touching a ray is seen from its first contact (no flicker, Fig. 5.4).
//  - I = T background + I_d; exposure, tone map and gamma as renderVolume.
// Cost: O(N^2) shadow rays (cheap next to the pixels for thousands of blobs) and O(pixels x blobs
// per ray x log) for the image; tiles of tileSize pixels keep the per-ray lists short.
// medium.extinction is sigma_t per unit mass density, medium.albedo Omega, medium.phaseG g;
// settings: background, ambient, exposure, gamma, toneMap (stepCells and surfaceAlbedo are unused).
//  - shade, when given, makes each pixel's radiance from what the ray integration found (the hook of
//    renderStochasticBlobs, stochastic_rendering.hpp); left empty, a pixel is I_d + T background
//    (I_d alone once T < kBlobMinTransmittance).
BlobRenderResult renderBlobs(const BlobSet& blobs, const Camera& camera, const std::vector<Light>& lights,
                             const Medium& medium, const VolumeRenderSettings& settings,
                             const BlobRenderSettings& blobSettings = {}, const BlobPixelShader& shade = {});

}  // namespace msim::render
