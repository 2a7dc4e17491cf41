#pragma once
// Light sources of the volume renderer: the "reduced incident" light I_ri of Stam ch. 5.1 (eq. 5.5)
// before it is attenuated by the medium. Colours are linear sRGB.
//   Directional: a collimated beam of irradiance intensity * colour [W/m^2] travelling along
//                `direction` (the sun); position is unused.
//   Point:       radiant intensity intensity * colour [W/sr] from `position` in all directions,
//                irradiance falling off as 1 / r^2; direction is unused.
//   Spot:        a point light restricted to the cone of half-angle spotAngleDegrees around
//                `direction`; the outer spotSoftness fraction of the angle fades smoothly to zero.
#include "msim/core/vec.hpp"

namespace msim::render {

struct Light {
  enum class Type { Directional, Point, Spot };
  Type type = Type::Directional;
  Vec3 position = Vec3::Zero();
  Vec3 direction = -Vec3::UnitY();  // direction of travel of the light (need not be unit length)
  Vec3 colour = Vec3::Ones();
  double intensity = 1.0;
  double spotAngleDegrees = 30.0;  // cone half-angle, in (0, 90]
  double spotSoftness = 0.2;       // in [0, 1]: 0 is a hard edge, 1 fades from the axis

  // std::invalid_argument naming the bad value (non-finite or negative colour or intensity, zero
  // direction for a directional or spot light, spot angle or softness out of range).
  void validate() const;
};

// Unshadowed light of one source at a point x.
struct LightSample {
  Vec3 toLight;     // unit direction from x towards the light (against the direction of travel)
  double distance;  // to the light; +infinity for a directional light
  Vec3 irradiance;  // [W/m^2] per channel, on a surface facing the light
};

// The light of a validated light at x. For point and spot lights the distance in the 1 / r^2
// falloff is at least minDistance, so a light sitting on a sample point stays finite (the renderer
// passes half a cell: the irradiance averaged over a cell around the light is of that order).
LightSample illuminate(const Light& light, const Vec3& x, double minDistance);

// Luminance Y of a linear sRGB colour (Rec. 709 weights).
inline double luminance(const Vec3& rgb) { return 0.2126 * rgb[0] + 0.7152 * rgb[1] + 0.0722 * rgb[2]; }

}  // namespace msim::render
