#include "msim/render/light.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

namespace msim::render {

namespace {

const char* typeName(Light::Type t) {
  switch (t) {
    case Light::Type::Directional: return "directional";
    case Light::Type::Point: return "point";
    case Light::Type::Spot: return "spot";
  }
  return "unknown";
}

// Smooth cone edge: 1 inside the inner cone, 0 outside the outer one, smoothstep in the cosine
// between them.
double spotFactor(const Light& l, const Vec3& fromLight) {
  const double outer = l.spotAngleDegrees * std::numbers::pi / 180.0;
  const double inner = outer * (1.0 - l.spotSoftness);
  const double c = l.direction.normalized().dot(fromLight);
  const double cosOuter = std::cos(outer), cosInner = std::cos(inner);
  if (c >= cosInner) return 1.0;
  if (c <= cosOuter) return 0.0;
  const double t = (c - cosOuter) / (cosInner - cosOuter);
  return t * t * (3.0 - 2.0 * t);
}

}  // namespace

void Light::validate() const {
  const std::string name = std::string(typeName(type)) + " light: ";
  if (!colour.allFinite() || (colour.array() < 0.0).any())
    throw std::invalid_argument(name + "colour must be finite and non-negative");
  if (!std::isfinite(intensity) || intensity < 0.0)
    throw std::invalid_argument(name + "intensity must be finite and non-negative, got " + std::to_string(intensity));
  if (type != Type::Point && (!direction.allFinite() || !(direction.norm() > 0.0)))
    throw std::invalid_argument(name + "direction must be finite and non-zero");
  if (type != Type::Directional && !position.allFinite()) throw std::invalid_argument(name + "position must be finite");
  if (type == Type::Spot) {
    if (!(spotAngleDegrees > 0.0 && spotAngleDegrees <= 90.0))
      throw std::invalid_argument(name + "spotAngleDegrees (cone half-angle) must be in (0, 90], got " +
                                  std::to_string(spotAngleDegrees));
    if (!(spotSoftness >= 0.0 && spotSoftness <= 1.0))
      throw std::invalid_argument(name + "spotSoftness must be in [0, 1], got " + std::to_string(spotSoftness));
  }
}

LightSample illuminate(const Light& light, const Vec3& x, double minDistance) {
  if (light.type == Light::Type::Directional)
    return {-light.direction.normalized(), std::numeric_limits<double>::infinity(), light.intensity * light.colour};
  const Vec3 d = light.position - x;
  const double r = d.norm();
  const Vec3 toLight = r > 0.0 ? Vec3(d / r) : Vec3(Vec3::UnitY());  // at the light itself any direction will do
  double e = light.intensity / std::pow(std::max(r, minDistance), 2);
  if (light.type == Light::Type::Spot) e *= spotFactor(light, -toLight);
  return {toLight, r, e * light.colour};
}

}  // namespace msim::render
