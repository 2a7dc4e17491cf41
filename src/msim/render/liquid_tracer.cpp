#include "msim/render/liquid_tracer.hpp"

#include <cmath>
#include <stdexcept>
#include <string>

#include "msim/render/dielectric.hpp"

namespace msim::render {

namespace {

constexpr double kInfinity = std::numeric_limits<double>::infinity();
constexpr double kMinWeight = 1e-4;      // branches carrying less of the camera ray are dropped
constexpr int kMaxLightCrossings = 16;   // surface crossings followed on a path to a light

}  // namespace

void LiquidOptics::validate() const {
  if (!std::isfinite(ior) || !(ior > 1.0))
    throw std::invalid_argument("liquid: ior must be greater than 1 (the air's), got " + std::to_string(ior));
  if (!absorption.allFinite() || (absorption.array() < 0.0).any())
    throw std::invalid_argument("liquid: absorption must be finite and >= 0 in every channel");
  if (maxBounces < 1 || maxBounces > 32)
    throw std::invalid_argument("liquid: maxBounces must be in [1, 32], got " + std::to_string(maxBounces));
}

Vec3 tracedRadiance(const Ray& ray, const TracedScene& scene) {
  SurfaceHit hit;
  const bool opaque = scene.opaqueHit(ray, kInfinity, hit);
  const TracedScene::Segment m = scene.medium(ray, opaque ? hit.t : kInfinity);
  const Vec3 end = opaque ? scene.opaqueRadiance(ray.origin + hit.t * ray.direction, hit) : scene.sky(ray.direction);
  return m.radiance + m.transmittance * end;
}

LiquidTracer::LiquidTracer(const LiquidSurface& surface, const LiquidOptics& optics)
    : surface_(&surface), optics_(optics), offset_(1e-4 * surface.cellSize()), tie_(1e-3 * surface.cellSize()) {
  optics_.validate();
}

Vec3 LiquidTracer::radiance(const Ray& ray, const TracedScene& scene) const {
  return trace(ray, surface_->inside(ray.origin), 0, 1.0, scene);
}

Vec3 LiquidTracer::trace(const Ray& ray, bool inside, int depth, double weight, const TracedScene& scene) const {
  if (weight < kMinWeight) return Vec3::Zero();
  return inside ? traceInside(ray, depth, weight, scene) : traceOutside(ray, depth, weight, scene);
}

Vec3 LiquidTracer::traceOutside(const Ray& ray, int depth, double weight, const TracedScene& scene) const {
  if (depth >= optics_.maxBounces) return tracedRadiance(ray, scene);  // no more splits: straight on
  SurfaceHit hit;
  const bool opaque = scene.opaqueHit(ray, kInfinity, hit);
  double tLiquid;
  if (!surface_->intersect(ray, 0.0, opaque ? hit.t - tie_ : kInfinity, false, tLiquid)) return tracedRadiance(ray, scene);
  const TracedScene::Segment m = scene.medium(ray, tLiquid);
  const Vec3 p = ray.origin + tLiquid * ray.direction;
  Vec3 n = surface_->normal(p);  // outward: against the entering ray, but for round-off at grazing angles
  if (n.dot(ray.direction) > 0.0) n = -n;
  const double R = fresnelReflectance(-n.dot(ray.direction), 1.0, optics_.ior);
  const double w = weight * m.transmittance;
  Vec3 L = R * trace({p + offset_ * n, reflect(ray.direction, n)}, false, depth + 1, w * R, scene);
  if (const auto t = refract(ray.direction, n, 1.0, optics_.ior))
    L += (1.0 - R) * trace({p - offset_ * n, *t}, true, depth + 1, w * (1.0 - R), scene);
  return m.radiance + m.transmittance * L;
}

Vec3 LiquidTracer::traceInside(const Ray& ray, int depth, double weight, const TracedScene& scene) const {
  double tExit;
  const bool exits = surface_->intersect(ray, 0.0, kInfinity, true, tExit);
  SurfaceHit hit;
  if (scene.opaqueHit(ray, exits ? tExit + tie_ : kInfinity, hit))
    return beerLambert(optics_.absorption, hit.t).cwiseProduct(scene.opaqueRadiance(ray.origin + hit.t * ray.direction, hit));
  if (!exits) return Vec3::Zero();  // cannot happen with the liquid clipped to its box
  const Vec3 absorbed = beerLambert(optics_.absorption, tExit);
  const Vec3 p = ray.origin + tExit * ray.direction;
  Vec3 n = surface_->normal(p);  // outward: along the leaving ray
  if (n.dot(ray.direction) < 0.0) n = -n;
  const Ray out{p + offset_ * n, ray.direction};
  if (depth >= optics_.maxBounces) return absorbed.cwiseProduct(trace(out, false, depth, weight, scene));
  const std::optional<Vec3> t = refract(ray.direction, n, optics_.ior, 1.0);
  const double R = t ? fresnelReflectance(n.dot(ray.direction), optics_.ior, 1.0) : 1.0;  // else total internal reflection
  const double w = weight * absorbed.maxCoeff();
  Vec3 L = R * trace({p - offset_ * n, reflect(ray.direction, n)}, true, depth + 1, w * R, scene);
  if (t) L += (1.0 - R) * trace({p + offset_ * n, *t}, false, depth + 1, w * (1.0 - R), scene);
  return absorbed.cwiseProduct(L);
}

Vec3 LiquidTracer::lightTransmittance(const Vec3& x, const Vec3& toLight, double distance) const {
  Vec3 transmitted = Vec3::Ones();
  const Ray ray{x, toLight};
  bool inside = surface_->inside(x);
  double t = 0.0;  // the last crossing; the search goes on from just past it
  for (int k = 0; k < kMaxLightCrossings; ++k) {
    double tCross;
    if (!surface_->intersect(ray, k == 0 ? 0.0 : t + offset_, distance, inside, tCross)) {
      if (inside) transmitted = transmitted.cwiseProduct(beerLambert(optics_.absorption, distance - t));  // a light in the liquid
      return transmitted;
    }
    if (inside) transmitted = transmitted.cwiseProduct(beerLambert(optics_.absorption, tCross - t));
    const double cosAir = std::abs(surface_->normal(x + tCross * toLight).dot(toLight));
    transmitted *= 1.0 - fresnelReflectance(cosAir, 1.0, optics_.ior);
    inside = !inside;
    t = tCross;
  }
  return transmitted;
}

}  // namespace msim::render
