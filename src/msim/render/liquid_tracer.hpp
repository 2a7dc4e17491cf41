#pragma once
// Whitted-style tracing of a liquid as a clear dielectric (Whitted 1980, "An improved illumination
// model for shaded display"): a ray that meets the surface splits into a reflected ray, weighted by
// the Fresnel reflectance R, and a refracted ray by Snell's law, weighted by T = 1 - R
// (dielectric.hpp); inside the liquid the light is dimmed by Beer-Lambert absorption,
// exp(-sigma_a d) per channel. Both branches are followed, deterministically (no Russian roulette:
// the same frame renders the same picture, without noise), until `maxBounces` splits; past that
// the ray goes on straight without splitting (a path that many surfaces deep carries little light,
// and stopping it dead would leave black holes where total internal reflection traps rays).
// Branches whose weight falls below 1e-4 of the camera ray's are dropped.
// Outside the liquid, rays see the rest of the scene (TracedScene: smoke, opaque surfaces, sky);
// inside it, no smoke (the liquid displaces it), the opaque surfaces under it (a floor, obstacles,
// meshes), dimmed by Beer-Lambert over the path. An opaque surface within 1e-3 of a cell of the
// liquid's surface wins: water touches the floor and walls of its tank with no gap, and a face of
// the box clipping the liquid there must not mirror the floor by total internal reflection.
// Light reaching a surface under the liquid follows the straight line to the light: Beer-Lambert
// over its length in the liquid and the Fresnel transmittance where it crosses the surface; the
// bending of that path (caustics) is not followed.
#include <limits>

#include "msim/render/camera.hpp"
#include "msim/render/liquid_surface.hpp"
#include "msim/render/surfaces.hpp"

namespace msim::render {

struct LiquidOptics {
  double ior = 1.33;  // refractive index of the liquid relative to the air around it (water: 1.33)
  // sigma_a [1/m] per linear RGB channel. Pure water (Pope & Fry 1997, Appl. Opt. 36, 8710) at the
  // dominant wavelengths of the sRGB primaries (612, 549, 465 nm): 0.26, 0.057 and 0.011 1/m, so a
  // metre of water keeps 77% of red, 94% of green and 99% of blue light.
  Vec3 absorption = Vec3(0.26, 0.057, 0.011);
  int maxBounces = 8;  // splits of one camera ray's deepest path

  // std::invalid_argument naming the value: ior <= 1 or not finite, absorption negative or not
  // finite, maxBounces outside [1, 32].
  void validate() const;
};

// The rest of the scene as the liquid's rays see it; the volume renderer implements it.
class TracedScene {
 public:
  struct Segment {
    Vec3 radiance = Vec3::Zero();  // added along the ray by the medium (smoke, fire)
    double transmittance = 1.0;    // of the medium, to the segment's end
  };

  virtual ~TracedScene() = default;
  // The nearest opaque surface with t in (0, tMax).
  virtual bool opaqueHit(const Ray& ray, double tMax, SurfaceHit& hit) const = 0;
  // Radiance leaving the surface point p of `hit` towards the ray's origin.
  virtual Vec3 opaqueRadiance(const Vec3& p, const SurfaceHit& hit) const = 0;
  // The medium along the ray for t in [0, tEnd].
  virtual Segment medium(const Ray& ray, double tEnd) const = 0;
  // Radiance of a ray that leaves the scene.
  virtual Vec3 sky(const Vec3& direction) const = 0;
};

// The radiance along a ray of a scene without liquid: the medium to the nearest opaque surface,
// then that surface's radiance, or the sky.
Vec3 tracedRadiance(const Ray& ray, const TracedScene& scene);

class LiquidTracer {
 public:
  // std::invalid_argument for invalid optics. The surface must outlive the tracer.
  LiquidTracer(const LiquidSurface& surface, const LiquidOptics& optics);

  // The radiance arriving at the ray's origin along it; a ray starting in the liquid (a camera
  // under water) starts inside.
  Vec3 radiance(const Ray& ray, const TracedScene& scene) const;

  // The fraction of a light's radiance that reaches x from the direction toLight (unit) at
  // `distance` through the liquid: the product of exp(-sigma_a d) over the path's stretches in the
  // liquid and of the Fresnel transmittance 1 - R(theta) at each surface it crosses, theta the
  // light's angle to the normal on the air side (for it, reciprocity makes the two directions of
  // crossing the same). Straight path: no refraction, no caustics.
  Vec3 lightTransmittance(const Vec3& x, const Vec3& toLight, double distance) const;

  const LiquidSurface& surface() const { return *surface_; }

 private:
  Vec3 trace(const Ray& ray, bool inside, int depth, double weight, const TracedScene& scene) const;
  Vec3 traceInside(const Ray& ray, int depth, double weight, const TracedScene& scene) const;
  Vec3 traceOutside(const Ray& ray, int depth, double weight, const TracedScene& scene) const;

  const LiquidSurface* surface_;
  LiquidOptics optics_;
  double offset_, tie_;  // new rays start offset_ off the surface; opaque surfaces within tie_ win
};

}  // namespace msim::render
