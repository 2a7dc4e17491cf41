#pragma once
// Smooth motion-field primitives of Stam ch. 6.3.1, instanced by affine transforms and summed
// (eq. 6.1): u(x) = sum_i m_i R_i u_p(M_i^-1 x), with M_i = translate * rotate * scale.
// Stam maps the local velocity with the whole linear part L = R S of M; we rotate only, so a
// field's magnitude stays a speed in m/s however large its region is scaled (for the vortices:
// circulation = magnitude * scale along local x). Each primitive lives in its local frame (centred
// at the origin, oriented along +z) and is localised by the decay W(d) = 2^(-d / d_half), the
// "half distance" of Stam's modeller (the seed leaves W unspecified; we pick the exponential so a
// field halves every d_half local units).
#include <string>
#include <vector>

#include <Eigen/Core>

#include "msim/core/vec.hpp"

namespace msim::fluid {

enum class MotionPrimitive {
  Uniform,      // constant wind along the axis, everywhere (no decay)
  Directional,  // W(z) e_z inside the half-infinite box |x|,|y| <= 1, z > 0 (optionally soft-edged)
  Radial,       // sign(d) W(|d|) x/|x|, d = |x| - 1: out of the unit sphere outside, inwards inside
  Cone,         // W(|x|) x/|x| inside the upward cone x^2 + y^2 < z^2, z > 0 (heat expansion)
  Source,       // W(|x|) x/|x|: point source (a sink with a negative magnitude)
  LineVortex,   // W(|x|)/(2 pi r) around the z axis, smoothed in a Lamb-Oseen core
  RingVortex,   // closest-point Biot-Savart of a circle of radius R in the xy plane (App. 6.A)
};

struct MotionFieldInstance {
  MotionPrimitive type = MotionPrimitive::Uniform;
  double magnitude = 1.0;             // [m/s] for winds; circulation [m^2/s] for vortices
  double halfDistance = 0.0;          // d_half in local units; <= 0 means no decay
  Vec3 position = Vec3::Zero();       // instance origin [m]
  Vec3 axis = Vec3::UnitZ();          // world direction of the local +z axis
  Vec3 scale = Vec3::Ones();          // local-to-world scale per local axis [m]
  double ringRadius = 1.0;            // R, local units (ring vortex)
  double coreRadius = 0.05;           // vortex core, local units: removes the 1/r singularity
  double edgeSoftness = 0.0;          // directional: fraction of the half-width over which the field
                                      // fades to zero (0: the hard cutoff printed in the seed)
};

class MotionField {
 public:
  MotionField() = default;
  explicit MotionField(std::vector<MotionFieldInstance> instances);

  // Velocity [m/s] at world position x.
  Vec3 velocity(const Vec3& x) const;
  std::size_t size() const { return compiled_.size(); }

  // The primitive in its local frame, magnitude 1 (exposed for tests of the seed's formulas).
  static Vec3 primitive(const MotionFieldInstance& instance, const Vec3& local);

 private:
  struct Compiled {
    MotionFieldInstance instance;
    Eigen::Matrix3d rotation;       // local -> world directions of the velocity
    Eigen::Matrix3d inverseLinear;  // (R S)^-1: world offsets -> local coordinates
  };
  std::vector<Compiled> compiled_;
};

MotionPrimitive parseMotionPrimitive(const std::string& name);
const std::vector<std::string>& motionPrimitiveNames();

}  // namespace msim::fluid
