#pragma once
// Stochastic rendering of density fields (Stam ch. 5.6, seed notes T16): the density is a random
// field with the blob field as its mean, rho = rho_bar + perturbation, and what the renderer needs
// of it is the statistics of the optical depth Gamma = integral rho du along each ray, not a finer
// density. Everything here is per ray:
//
//  - A homogeneous isotropic perturbation q of standard deviation s and correlation s^2 c(r)
//    (c(0) = 1, Gaussian exp(-r^2 / (2 l^2)) as in Stam, or exponential exp(-r / l)) gives, over a
//    segment of length L, Var[integral q du] = integral integral s^2 c(u - u') du du'   (eq. 5.27)
//    = 2 s^2 integral_0^L (L - r) c(r) dr, in closed form for both correlations.
//  - Stam's quasi-homogeneous blobs (eq. 5.26): rho_k = rho_bar_k + sigma_rho,k Q, Q of unit variance
//    and correlation c, sigma_rho,k^2 = epsilon F_eta(rho_bar_k), F_eta(t) = min(t, eta) (the clamped
//    variance of Fig. 5.24). When c is much shorter than the blob, eq. 5.27 reduces to eq. 5.28-5.29:
//    Var Gamma_k = epsilon l_c integral F_eta(rho_bar_k) du, with l_c = integral_-inf^inf c(r) dr
//    (l sqrt(2 pi) Gaussian, 2 l exponential). Stam prints C_Q(0) epsilon integral F_eta, which is
//    not a length squared times a density squared: his epsilon absorbs l_c; we keep the two apart
//    so epsilon stays the density variance per unit density of eq. 5.26. The blobs' perturbations
//    are taken as independent (each samples Q at its own closest point, eq. 5.30), so variances add.
//  - The clamped integral splits at u_k^-+ = c_k -+ du_k where m_k G(|x_u - x_k|) = eta (T16):
//    du_k = sigma sqrt(2 ln(m_k exp(-d_k^2 / (2 sigma^2)) / ((2 pi)^(3/2) sigma^3 eta))) (the seed's
//    erratum: the thesis prints h^3 and no leading sigma); each piece is eq. 5.17.
//  - With Gamma Gaussian of mean M and variance V, the expected transparency is the log-normal mean
//    E[exp(-sigma_t Gamma)] = exp(-sigma_t M + sigma_t^2 V / 2): the average picture of all
//    realisations is brighter than the mean density's (Jensen), and V = 0 is Beer-Lambert (eq. 5.6).
//    (A Gaussian Gamma can be negative; for V << M^2 the weight of those realisations is negligible.)
//  - One realisation (eq. 5.30): Gamma_omega = sum_k (Gamma_bar_k + sigma_Gamma,k Q_omega(x_ck)),
//    x_ck the ray's point closest to blob k, so a static scene looks the same from frame to frame;
//    clamped at 0 (the seed's required safeguard: a density is not negative).
#include <cstdint>
#include <functional>
#include <limits>
#include <vector>

#include "msim/render/blobs.hpp"

namespace msim::render {

struct Correlation {
  enum class Kind { Gaussian, Exponential };
  Kind kind = Kind::Gaussian;
  double length = 0.05;  // l [m], > 0

  void validate() const;  // std::invalid_argument for a length that is not positive and finite
  double operator()(double r) const;  // c(r), c(0) = 1
  double integralLength() const;      // l_c = integral_-inf^inf c(r) dr
};

struct OpticalDepthStatistics {
  double mean = 0.0;      // E[Gamma] [kg/m^2]
  double variance = 0.0;  // Var[Gamma]
};

// Var[integral_0^L q du] for a homogeneous perturbation of standard deviation stdDev (eq. 5.27).
// std::invalid_argument for a negative or non-finite stdDev or length.
double lineIntegralVariance(const Correlation& correlation, double stdDev, double length);

// Gamma over a segment of length L of a homogeneous field of mean meanDensity and standard
// deviation stdDev: {meanDensity L, lineIntegralVariance}. std::invalid_argument for bad input.
OpticalDepthStatistics homogeneousSegmentStatistics(double meanDensity, double stdDev, const Correlation& correlation,
                                                    double length);

// exp(-extinction mean + extinction^2 variance / 2). std::invalid_argument for a negative or
// non-finite extinction or variance, or a non-finite mean.
double expectedTransparency(double extinction, const OpticalDepthStatistics& statistics);

struct StochasticBlobParameters {
  double epsilon = 0.0;  // variance per unit density of the perturbation (eq. 5.26), >= 0
  double eta = std::numeric_limits<double>::infinity();  // clamp of F_eta, > 0 (infinite: no clamp)
  Correlation correlation;

  void validate() const;  // std::invalid_argument naming the bad value
};

// integral_a^b min(m_k G(x_u - x_k), eta) du, a <= b (the three-piece split above).
double clampedBlobLineIntegral(const Blob& blob, const Ray& ray, double a, double b, double eta);

// Mean sum_k Gamma_bar_k and variance sum_k epsilon l_c integral F_eta(rho_bar_k) du over [a, b].
OpticalDepthStatistics blobRayStatistics(const BlobSet& blobs, const Ray& ray, double a, double b,
                                         const StochasticBlobParameters& parameters);

// One realisation (eq. 5.30) over [a, b], q(x) a unit-variance realisation of Q (e.g. a periodic
// table, T16), clamped at 0.
double realisedOpticalDepth(const BlobSet& blobs, const Ray& ray, double a, double b,
                            const StochasticBlobParameters& parameters, const std::function<double(const Vec3&)>& q);

// A deterministic smooth realisation of Q (unit variance, correlation c) for eq. 5.30: random
// Fourier features q(x) = sqrt(2 / N) sum_i cos(k_i . x + phi_i), phi_i uniform in [0, 2 pi), k_i
// drawn from the spectral density of c (Bochner: E[cos(k . r)] = c(r)), N(0, I / l^2) for the
// Gaussian and the 3D Cauchy z / (l |w|) (z ~ N(0, I), w ~ N(0, 1)) for the exponential. Over
// seeds, q(x) has mean 0, variance 1 and correlation c exactly, and is near-Gaussian (a sum of N
// independent terms); one seed gives a smooth field that, unlike Stam's periodic 32^3 table
// (T16), does not repeat. std::invalid_argument for a bad correlation or terms < 1.
class FourierNoise {
 public:
  FourierNoise(const Correlation& correlation, std::uint64_t seed, int terms = 128);
  double operator()(const Vec3& x) const;

 private:
  std::vector<Vec3> wavevectors_;
  std::vector<double> phases_;
  double amplitude_;
};

// What renderStochasticBlobs draws.
enum class StochasticImage {
  Realisation,  // one realisation of the density (eq. 5.30): the wispy detail
  Expected,     // the average picture over all realisations (log-normal mean transparency)
};

struct StochasticRenderSettings {
  StochasticBlobParameters parameters;
  StochasticImage image = StochasticImage::Realisation;
  std::uint64_t seed = 1;  // of the FourierNoise q (Realisation only)
  int noiseTerms = 128;

  void validate() const;  // parameters.validate(), std::invalid_argument for noiseTerms < 1
};

// Stochastic rendering of the blob set (T16's per-ray algorithm) on top of renderBlobs: each camera
// ray keeps renderBlobs' mean-density integration - the scattered light I_d and its opacity 1 - T,
// T = exp(-sigma_t Gamma_bar), Gamma_bar the sum of the chords' exact integrals - and with the
// average source J_avg = I_d / (1 - T) (the opacity-weighted mean of the blobs' J along the ray;
// T16 takes the source to depend only on the mean density, smoothed by the ray average and by
// scattering) the pixel is
//   I = tau B + (1 - tau) J_avg = I_d + tau B + (T - tau) J_avg,
// B the background (0 where tau < kBlobMinTransmittance, as renderBlobs). tau is
//  - Realisation: exp(-sigma_t max(0, Gamma_bar + delta)), delta = sum_k sigma_Gamma,k q(x_ck) over
//    the ray's chords (eq. 5.30; sigma_Gamma,k^2 = epsilon l_c integral F_eta over the chord, eq.
//    5.29), q = FourierNoise(seed): a fixed seed gives the same image every frame;
//  - Expected: min(1, T exp(sigma_t^2 V / 2)), V = sum_k sigma_Gamma,k^2 (independent blobs, as
//    blobRayStatistics): E[exp(-sigma_t Gamma)] for Gaussian Gamma, clamped at 1 because the
//    realisations' Gamma is clamped at 0. I is linear in tau, so with J_avg fixed this is exactly
//    the mean of the realisations' pictures.
// With epsilon = 0 both are renderBlobs' image. Cost: renderBlobs plus one clamped line integral
// (eq. 5.17 twice) and one q (N cosines) per chord.
BlobRenderResult renderStochasticBlobs(const BlobSet& blobs, const Camera& camera, const std::vector<Light>& lights,
                                       const Medium& medium, const VolumeRenderSettings& settings,
                                       const StochasticRenderSettings& stochastic,
                                       const BlobRenderSettings& blobSettings = {});

}  // namespace msim::render
