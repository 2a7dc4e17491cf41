#include "msim/render/dielectric.hpp"

#include <algorithm>
#include <cmath>

namespace msim::render {

double fresnelReflectance(double cosIncident, double n1, double n2) {
  const double cosI = std::clamp(cosIncident, 0.0, 1.0);
  const double sinT2 = (n1 / n2) * (n1 / n2) * (1.0 - cosI * cosI);
  if (sinT2 >= 1.0) return 1.0;  // total internal reflection
  const double cosT = std::sqrt(1.0 - sinT2);
  const double rs = (n1 * cosI - n2 * cosT) / (n1 * cosI + n2 * cosT);
  const double rp = (n2 * cosI - n1 * cosT) / (n2 * cosI + n1 * cosT);
  return 0.5 * (rs * rs + rp * rp);
}

Vec3 reflect(const Vec3& d, const Vec3& n) { return d - 2.0 * d.dot(n) * n; }

std::optional<Vec3> refract(const Vec3& d, const Vec3& n, double n1, double n2) {
  const Vec3 m = d.dot(n) < 0.0 ? n : Vec3(-n);  // the normal on the side the ray comes from
  const double cosI = std::min(-d.dot(m), 1.0);
  const double eta = n1 / n2;
  const double sinT2 = eta * eta * (1.0 - cosI * cosI);
  if (sinT2 >= 1.0) return std::nullopt;
  const double cosT = std::sqrt(1.0 - sinT2);
  return Vec3((eta * d + (eta * cosI - cosT) * m).normalized());
}

Vec3 beerLambert(const Vec3& absorption, double length) {
  return (-absorption.array() * std::max(length, 0.0)).exp().matrix();
}

}  // namespace msim::render
