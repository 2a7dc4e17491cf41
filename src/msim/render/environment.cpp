#include "msim/render/environment.hpp"

#include <cmath>
#include <numbers>
#include <stdexcept>
#include <string>

namespace msim::render {

namespace {

bool finiteNonNegative(const Vec3& v) { return v.allFinite() && (v.array() >= 0.0).all(); }
bool unitInterval(const Vec3& v) { return finiteNonNegative(v) && (v.array() <= 1.0).all(); }

}  // namespace

void Sky::validate() const {
  if (!finiteNonNegative(zenith)) throw std::invalid_argument("sky: zenith radiance must be finite and non-negative");
  if (!finiteNonNegative(horizon)) throw std::invalid_argument("sky: horizon radiance must be finite and non-negative");
  if (!(sunRadiusDegrees > 0.0 && sunRadiusDegrees <= 30.0))
    throw std::invalid_argument("sky: sun radius must be in (0, 30] degrees, got " + std::to_string(sunRadiusDegrees));
}

Vec3 Sky::radiance(const Vec3& direction, const std::vector<Light>& lights, const Vec3& background) const {
  if (!enabled) return background;
  const double up = std::max(direction.y(), 0.0);
  Vec3 L = horizon + up * (zenith - horizon);
  const double cosRadius = std::cos(sunRadiusDegrees * std::numbers::pi / 180.0);
  const double solidAngle = 2.0 * std::numbers::pi * (1.0 - cosRadius);
  for (const Light& light : lights)
    if (light.type == Light::Type::Directional && direction.dot(-light.direction.normalized()) >= cosRadius)
      L += (light.intensity / solidAngle) * light.colour;
  return L;
}

void Floor::validate() const {
  if (!std::isfinite(height)) throw std::invalid_argument("floor: height must be finite");
  if (!unitInterval(albedo)) throw std::invalid_argument("floor: albedo must be in [0, 1]");
  if (!unitInterval(tileAlbedo)) throw std::invalid_argument("floor: tile albedo must be in [0, 1]");
  if (!std::isfinite(tile) || tile < 0.0)
    throw std::invalid_argument("floor: tile must be finite and >= 0, got " + std::to_string(tile));
}

bool Floor::intersect(const Ray& ray, double tMax, SurfaceHit& hit) const {
  if (!enabled || !(ray.direction.y() < 0.0) || !(ray.origin.y() > height)) return false;
  const double t = (height - ray.origin.y()) / ray.direction.y();
  if (!(t > 0.0 && t < tMax)) return false;
  hit.t = t;
  hit.normal = hit.offsetNormal = Vec3::UnitY();
  hit.albedo = albedo;
  if (tile > 0.0) {
    const Vec3 p = ray.origin + t * ray.direction;
    const long long parity = static_cast<long long>(std::floor(p.x() / tile)) + static_cast<long long>(std::floor(p.z() / tile));
    if (parity % 2 != 0) hit.albedo = tileAlbedo;
  }
  return true;
}

}  // namespace msim::render
