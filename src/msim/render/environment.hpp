#pragma once
// What surrounds the simulated box: a sky that rays leaving the scene see, with the directional
// lights as sun disks, and a floor under the box. Water is seen mostly by what it reflects and
// refracts, so a liquid picture needs both: the sky and the sun's highlight in the reflections,
// a floor seen through the water. Both are off by default (rays leaving the scene then see the
// constant `background`, as smoke pictures always have).
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/render/camera.hpp"
#include "msim/render/light.hpp"
#include "msim/render/surfaces.hpp"

namespace msim::render {

// A clear sky: radiance from the horizon to the zenith, linear in the direction's up component
// (+y), the horizon's below it; each directional light a disk of angular radius sunRadiusDegrees
// around the direction it comes from, of uniform radiance E / Omega, Omega = 2 pi (1 - cos r) its
// solid angle, so the disk delivers the light's irradiance E to a surface facing it (the real sun:
// 0.27 degrees). A mirror-like surface shows the disk as a highlight of its size; a larger disk
// makes a softer, larger highlight of the same total power.
struct Sky {
  bool enabled = false;
  Vec3 zenith = Vec3(0.25, 0.4, 0.75);   // radiance straight up, linear RGB
  Vec3 horizon = Vec3(0.7, 0.78, 0.9);   // radiance at and below the horizon
  double sunRadiusDegrees = 2.0;         // in (0, 30]

  // std::invalid_argument naming the value: negative or non-finite radiance, sun radius outside (0, 30].
  void validate() const;
  // Radiance seen along `direction` (unit); `background` when disabled.
  Vec3 radiance(const Vec3& direction, const std::vector<Light>& lights, const Vec3& background) const;
};

// An infinite horizontal plane y = height under the box (a table, the ground), Lambertian, with
// square tiles of `tile` metres alternating between albedo and tileAlbedo (tile 0: plain), so that
// the bending of its lines shows refraction through a liquid above it.
struct Floor {
  bool enabled = false;
  double height = 0.0;  // [m]
  Vec3 albedo = Vec3::Constant(0.6);
  double tile = 0.0;  // [m], 0 for one colour
  Vec3 tileAlbedo = Vec3::Constant(0.3);

  // std::invalid_argument naming the value: albedos outside [0, 1], a negative tile, non-finite height.
  void validate() const;
  // Hit with t in (0, tMax) from above (the floor is seen from above only).
  bool intersect(const Ray& ray, double tMax, SurfaceHit& hit) const;
};

}  // namespace msim::render
