#include "msim/render/stochastic_rendering.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

#include "msim/core/rng.hpp"

namespace msim::render {

namespace {

void requireNonNegative(double v, const char* what) {
  if (!std::isfinite(v) || v < 0.0) throw std::invalid_argument(std::string(what) + " must be finite and >= 0, got " + std::to_string(v));
}

}  // namespace

void Correlation::validate() const {
  if (!std::isfinite(length) || !(length > 0.0))
    throw std::invalid_argument("correlation: length must be positive and finite, got " + std::to_string(length));
}

double Correlation::operator()(double r) const {
  return kind == Kind::Gaussian ? std::exp(-r * r / (2.0 * length * length)) : std::exp(-std::abs(r) / length);
}

double Correlation::integralLength() const {
  return kind == Kind::Gaussian ? length * std::sqrt(2.0 * std::numbers::pi) : 2.0 * length;
}

double lineIntegralVariance(const Correlation& correlation, double stdDev, double length) {
  correlation.validate();
  requireNonNegative(stdDev, "lineIntegralVariance: stdDev");
  requireNonNegative(length, "lineIntegralVariance: length");
  const double l = correlation.length, L = length;
  // 2 s^2 integral_0^L (L - r) c(r) dr, the two terms integrated separately.
  const double integral =
      correlation.kind == Correlation::Kind::Gaussian
          ? L * l * std::sqrt(0.5 * std::numbers::pi) * std::erf(L / (std::numbers::sqrt2 * l)) -
                l * l * -std::expm1(-L * L / (2.0 * l * l))
          : l * L - l * l * -std::expm1(-L / l);
  return 2.0 * stdDev * stdDev * integral;
}

OpticalDepthStatistics homogeneousSegmentStatistics(double meanDensity, double stdDev, const Correlation& correlation,
                                                    double length) {
  if (!std::isfinite(meanDensity))
    throw std::invalid_argument("homogeneousSegmentStatistics: meanDensity must be finite, got " + std::to_string(meanDensity));
  return {meanDensity * length, lineIntegralVariance(correlation, stdDev, length)};
}

double expectedTransparency(double extinction, const OpticalDepthStatistics& statistics) {
  requireNonNegative(extinction, "expectedTransparency: extinction");
  requireNonNegative(statistics.variance, "expectedTransparency: variance");
  if (!std::isfinite(statistics.mean))
    throw std::invalid_argument("expectedTransparency: mean must be finite, got " + std::to_string(statistics.mean));
  return std::exp(-extinction * statistics.mean + 0.5 * extinction * extinction * statistics.variance);
}

void StochasticBlobParameters::validate() const {
  requireNonNegative(epsilon, "stochastic blobs: epsilon");
  if (std::isnan(eta) || !(eta > 0.0)) throw std::invalid_argument("stochastic blobs: eta must be positive, got " + std::to_string(eta));
  correlation.validate();
}

double clampedBlobLineIntegral(const Blob& blob, const Ray& ray, double a, double b, double eta) {
  if (std::isnan(eta) || !(eta > 0.0)) throw std::invalid_argument("clampedBlobLineIntegral: eta must be positive, got " + std::to_string(eta));
  const double full = blobLineIntegral(blob, ray, a, b);  // checks a <= b
  const Vec3 v = blob.centre - ray.origin;
  const double c = v.dot(ray.direction), d2 = std::max(0.0, v.squaredNorm() - c * c), s = blob.width;
  // Peak of m G along the ray over eta; below 1 the clamp never acts (u+ = u- = c_k).
  const double ratio = blob.mass * std::exp(-d2 / (2.0 * s * s)) / (std::pow(2.0 * std::numbers::pi, 1.5) * s * s * s * eta);
  if (!(ratio > 1.0)) return full;
  const double du = s * std::sqrt(2.0 * std::log(ratio));
  const double lo = std::max(a, c - du), hi = std::min(b, c + du);
  if (!(hi > lo)) return full;
  // Inside [u-, u+] the density exceeds eta: replace its integral there by eta times the length.
  return full - blobLineIntegral(blob, ray, lo, hi) + eta * (hi - lo);
}

OpticalDepthStatistics blobRayStatistics(const BlobSet& blobs, const Ray& ray, double a, double b,
                                         const StochasticBlobParameters& parameters) {
  parameters.validate();
  OpticalDepthStatistics st;
  const double scale = parameters.epsilon * parameters.correlation.integralLength();
  for (const Blob& blob : blobs.blobs()) {
    st.mean += blobLineIntegral(blob, ray, a, b);
    if (scale > 0.0) st.variance += scale * clampedBlobLineIntegral(blob, ray, a, b, parameters.eta);
  }
  return st;
}

double realisedOpticalDepth(const BlobSet& blobs, const Ray& ray, double a, double b,
                            const StochasticBlobParameters& parameters, const std::function<double(const Vec3&)>& q) {
  parameters.validate();
  const double scale = parameters.epsilon * parameters.correlation.integralLength();
  double gamma = 0.0;
  for (const Blob& blob : blobs.blobs()) {
    gamma += blobLineIntegral(blob, ray, a, b);
    if (scale > 0.0) {
      const double closest = std::clamp((blob.centre - ray.origin).dot(ray.direction), a, b);
      gamma += std::sqrt(scale * clampedBlobLineIntegral(blob, ray, a, b, parameters.eta)) *
               q(ray.origin + closest * ray.direction);
    }
  }
  return std::max(0.0, gamma);
}

FourierNoise::FourierNoise(const Correlation& correlation, std::uint64_t seed, int terms) {
  correlation.validate();
  if (terms < 1) throw std::invalid_argument("FourierNoise: terms must be >= 1, got " + std::to_string(terms));
  Rng rng(seed);
  for (int i = 0; i < terms; ++i) {
    const Vec3 z(rng.normal(), rng.normal(), rng.normal());
    double scale = 1.0 / correlation.length;
    if (correlation.kind == Correlation::Kind::Exponential) {
      double w = 0.0;
      while (w == 0.0) w = rng.normal();
      scale /= std::abs(w);
    }
    wavevectors_.push_back(scale * z);
    phases_.push_back(rng.uniform(0.0, 2.0 * std::numbers::pi));
  }
  amplitude_ = std::sqrt(2.0 / terms);
}

double FourierNoise::operator()(const Vec3& x) const {
  double sum = 0.0;
  for (std::size_t i = 0; i < phases_.size(); ++i) sum += std::cos(wavevectors_[i].dot(x) + phases_[i]);
  return amplitude_ * sum;
}

void StochasticRenderSettings::validate() const {
  parameters.validate();
  if (noiseTerms < 1) throw std::invalid_argument("stochastic rendering: noiseTerms must be >= 1, got " + std::to_string(noiseTerms));
}

BlobRenderResult renderStochasticBlobs(const BlobSet& blobs, const Camera& camera, const std::vector<Light>& lights,
                                       const Medium& medium, const VolumeRenderSettings& settings,
                                       const StochasticRenderSettings& stochastic,
                                       const BlobRenderSettings& blobSettings) {
  stochastic.validate();
  const FourierNoise q(stochastic.parameters.correlation, stochastic.seed, stochastic.noiseTerms);
  const double scale = stochastic.parameters.epsilon * stochastic.parameters.correlation.integralLength();
  const double eta = stochastic.parameters.eta, sigmaT = medium.extinction;
  const bool realisation = stochastic.image == StochasticImage::Realisation;
  const BlobPixelShader shade = [&](int, int, const Ray& ray, std::span<const BlobChord> chords,
                                    const BlobRayIntegral& integral) -> Vec3 {
    double mean = 0.0, delta = 0.0, variance = 0.0;
    for (const BlobChord& chord : chords) {
      mean += chord.depth;
      if (!(scale > 0.0)) continue;
      const Blob& blob = blobs.blobs()[chord.blob];
      const double v = scale * clampedBlobLineIntegral(blob, ray, chord.in, chord.out, eta);  // eq. 5.29
      if (realisation) {
        const double closest = std::clamp((blob.centre - ray.origin).dot(ray.direction), chord.in, chord.out);
        delta += std::sqrt(v) * q(ray.origin + closest * ray.direction);  // eq. 5.30
      } else {
        variance += v;
      }
    }
    // T of the mean density over the whole ray (renderBlobs' sweep gives the same up to round-off
    // but stops at T < 1e-4); delta = 0 gives tau = T exactly.
    const double T = std::exp(-sigmaT * mean);
    const double tau = realisation ? std::exp(-sigmaT * std::max(0.0, mean + delta))
                                   : std::min(1.0, T * std::exp(0.5 * sigmaT * sigmaT * variance));
    const Vec3 averageSource = integral.opacity > 0.0 ? Vec3(integral.scattered / integral.opacity) : Vec3::Zero();
    const Vec3 background = tau >= kBlobMinTransmittance ? settings.background : Vec3::Zero();  // as renderBlobs
    return integral.scattered + tau * background + (T - tau) * averageSource;
  };
  return renderBlobs(blobs, camera, lights, medium, settings, blobSettings, shade);
}

}  // namespace msim::render
