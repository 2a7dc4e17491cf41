#pragma once
// Optics of a smooth interface between two dielectrics (air and water) and of absorption inside
// one: what the liquid renderer (liquid_tracer.hpp) needs to split a ray at the surface and to dim
// it along its path through the liquid. Directions are unit vectors; normals point to the side the
// ray comes from or to either side where stated.
#include <optional>

#include "msim/core/vec.hpp"

namespace msim::render {

// Unpolarised Fresnel reflectance of a smooth interface (Hecht, Optics, ch. 4.6; Born & Wolf ch.
// 1.5.2): light in a medium of index n1 meets one of index n2 at the angle theta_i to the normal.
// With cos_t from Snell's law, n1 sin_i = n2 sin_t,
//   r_s = (n1 cos_i - n2 cos_t) / (n1 cos_i + n2 cos_t),  r_p = (n2 cos_i - n1 cos_t) / (n2 cos_i + n1 cos_t),
//   R = (r_s^2 + r_p^2) / 2,
// the mean of the two polarisations because sunlight and sky light are unpolarised. The exact
// equations rather than Schlick's approximation: Schlick is off by up to ~10% of R near the critical
// angle inside water, where total internal reflection makes the underside of a surface a mirror.
// Beyond the critical angle (n1 > n2 and sin_t > 1) R = 1. Both directions are the same formula:
// R(theta_i; n1, n2) = R(theta_t; n2, n1) (Stokes' reciprocity), and T = 1 - R since a dielectric
// absorbs nothing at the interface. cosIncident in [0, 1] (clamped), n1, n2 > 0.
double fresnelReflectance(double cosIncident, double n1, double n2);

// Mirror direction of d about the normal n (either side): d - 2 (d . n) n.
Vec3 reflect(const Vec3& d, const Vec3& n);

// Snell's law in vector form (e.g. Pharr, Jakob & Humphreys, PBRT 3rd ed., ch. 8.2.3): the ray d in
// index n1 crosses into index n2 through a surface with normal n (either side); the transmitted
// direction t = eta d + (eta cos_i - cos_t) m, m the normal on the incident side (m . d < 0),
// eta = n1 / n2, cos_t = sqrt(1 - eta^2 (1 - cos_i^2)). It lies in the plane of d and n with
// n1 sin_i = n2 sin_t. Nothing beyond the critical angle (total internal reflection).
std::optional<Vec3> refract(const Vec3& d, const Vec3& n, double n1, double n2);

// Beer-Lambert law (Bouguer-Lambert-Beer; Stam eq. 5.6 for a homogeneous medium): the fraction of
// light left after a path of `length` [m] through a medium of absorption coefficient sigma_a
// [1/m] per channel, exp(-sigma_a length). Water absorbs red most (its overtone bands of the O-H
// stretch at 740 and 970 nm reach into the visible), so white light turns blue-green with depth.
Vec3 beerLambert(const Vec3& absorption, double length);

}  // namespace msim::render
