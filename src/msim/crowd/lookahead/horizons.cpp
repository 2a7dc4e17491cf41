#include "msim/crowd/lookahead/horizons.hpp"

#include <algorithm>
#include <cmath>

namespace msim::crowd::lookahead {

double HorizonSchedule::horizon(int level) const { return level <= 0 ? 0.0 : std::ldexp(baseStep, level - 1); }

double HorizonSchedule::bandStart(int level) const {
  return level <= 0 ? 0.0 : neighbourDist + 2.0 * maxSpeed * horizon(level - 1);
}

int HorizonSchedule::levelOfDistance(double distance) const {
  return levelInBands(distance, levels, [this](int i) { return bandStart(i); });
}

double HorizonSchedule::effectiveRadius(double radius, int level) const { return radius / std::pow(coarsening, level); }

namespace {

// e^(-x) I0(x) for x >= 0 without overflow: the standard library's I0 up to 500, its asymptotic
// series beyond (relative error below 1e-9 there).
double scaledBesselI0(double x) {
  if (x < 500.0) return std::cyl_bessel_i(0.0, x) * std::exp(-x);
  return 1.0 / std::sqrt(2.0 * std::acos(-1.0) * x) * (1.0 + 1.0 / (8.0 * x) + 9.0 / (128.0 * x * x));
}

// The probability that a disc of radius r, its centre Gaussian about a point at distance d with
// standard deviation sigma per axis, covers that point: the Rice distribution's mass within r,
// integral_0^r (q / s^2) exp(-(q - d)^2 / (2 s^2)) e^(-q d / s^2) I0(q d / s^2) dq, by Simpson's
// rule over the part of [0, r] within 10 sigma of d (the integrand is below e^-50 elsewhere).
double coverage(double radius, double sigma, double d) {
  const double lo = std::max(0.0, d - 10.0 * sigma), hi = std::min(radius, d + 10.0 * sigma);
  if (!(hi > lo)) return 0.0;
  const int intervals = 400;
  const double s2 = sigma * sigma, h = (hi - lo) / intervals;
  double sum = 0.0;
  for (int k = 0; k <= intervals; ++k) {
    const double q = lo + k * h;
    const double f = q / s2 * std::exp(-(q - d) * (q - d) / (2.0 * s2)) * scaledBesselI0(q * d / s2);
    sum += f * (k == 0 || k == intervals ? 1.0 : (k % 2 == 1 ? 4.0 : 2.0));
  }
  return sum * h / 3.0;
}

}  // namespace

double gaussianCoverageRadius(double radius, double sigma, double p) {
  if (!(sigma > 0.0)) return radius;
  // The coverage falls with the distance from the blob's centre, where it is 1 - e^(-r^2 / 2 s^2).
  if (1.0 - std::exp(-radius * radius / (2.0 * sigma * sigma)) < p) return 0.0;
  double inside = 0.0, outside = radius + 10.0 * sigma;  // coverage >= p at `inside`, < p at `outside`
  for (int k = 0; k < 60; ++k) {
    const double middle = 0.5 * (inside + outside);
    (coverage(radius, sigma, middle) >= p ? inside : outside) = middle;
  }
  return inside;
}

}  // namespace msim::crowd::lookahead
