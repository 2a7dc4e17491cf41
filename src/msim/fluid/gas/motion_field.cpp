#include "msim/fluid/gas/motion_field.hpp"

#include <algorithm>
#include <cmath>
#include <numbers>
#include <stdexcept>

#include <Eigen/Geometry>

namespace msim::fluid {

namespace {

double decay(double d, double halfDistance) {
  return halfDistance > 0.0 ? std::exp2(-d / halfDistance) : 1.0;
}

// Rotation taking +z to `axis` (the shortest arc; any roll about the axis is equivalent for the
// axisymmetric primitives, and the directional box is square).
Eigen::Matrix3d frameFor(const Vec3& axis) {
  const Vec3 z = axis.normalized();
  return Eigen::Quaterniond::FromTwoVectors(Vec3::UnitZ(), z).toRotationMatrix();
}

}  // namespace

MotionField::MotionField(std::vector<MotionFieldInstance> instances) {
  compiled_.reserve(instances.size());
  for (auto& inst : instances) {
    if (inst.axis.norm() == 0.0) throw std::invalid_argument("motion field axis must be non-zero");
    Compiled c;
    c.instance = inst;
    if ((inst.scale.array() <= 0.0).any()) throw std::invalid_argument("motion field scale must be positive");
    c.rotation = frameFor(inst.axis);
    c.inverseLinear = (c.rotation * inst.scale.asDiagonal()).inverse();
    compiled_.push_back(c);
  }
}

Vec3 MotionField::primitive(const MotionFieldInstance& inst, const Vec3& p) {
  const double h = inst.halfDistance;
  switch (inst.type) {
    case MotionPrimitive::Uniform:
      return Vec3::UnitZ();
    case MotionPrimitive::Directional: {
      if (std::abs(p.x()) > 1.0 || std::abs(p.y()) > 1.0 || p.z() <= 0.0) return Vec3::Zero();
      // Stam notes the hard cutoff "can be smoothed out by multiplying the field by a smooth
      // function which is zero outside of the unit square": a smoothstep over the outer band.
      double mask = 1.0;
      if (inst.edgeSoftness > 0.0)
        for (double t : {std::abs(p.x()), std::abs(p.y())}) {
          const double s = std::clamp((1.0 - t) / inst.edgeSoftness, 0.0, 1.0);
          mask *= s * s * (3.0 - 2.0 * s);
        }
      return mask * decay(p.z(), h) * Vec3::UnitZ();
    }
    case MotionPrimitive::Radial: {
      // Printed as (d/|d|) W(d) x/(d+1); d + 1 = |x|, and W takes the distance to the sphere.
      const double r = p.norm();
      const double d = r - 1.0;
      if (r == 0.0 || d == 0.0) return Vec3::Zero();
      return (d > 0.0 ? 1.0 : -1.0) * decay(std::abs(d), h) * p / r;
    }
    case MotionPrimitive::Cone: {
      // The printed condition x^2 + y^2 < z^2 is a double cone; heat expands upwards only.
      const double r = p.norm();
      if (p.z() <= 0.0 || p.x() * p.x() + p.y() * p.y() >= p.z() * p.z()) return Vec3::Zero();
      return decay(r, h) * p / r;
    }
    case MotionPrimitive::Source: {
      const double r = p.norm();
      if (r == 0.0) return Vec3::Zero();
      return decay(r, h) * p / r;
    }
    case MotionPrimitive::LineVortex: {
      // Stam: W(|x|)/(2 pi (x^2+y^2)) (-y, x, 0), circulation 1 about the z axis. The Lamb-Oseen
      // factor 1 - exp(-r^2/rc^2) leaves that circulation intact outside the core and makes the
      // field finite (solid-body rotation) inside it.
      const double r2 = p.x() * p.x() + p.y() * p.y();
      if (r2 == 0.0) return Vec3::Zero();
      const double rc2 = inst.coreRadius * inst.coreRadius;
      const double core = rc2 > 0.0 ? -std::expm1(-r2 / rc2) : 1.0;
      return decay(p.norm(), h) * core / (2.0 * std::numbers::pi * r2) * Vec3(-p.y(), p.x(), 0.0);
    }
    case MotionPrimitive::RingVortex: {
      // App. 6.A with (x1, y1) = R (x, y)/rho: the numerator's last term (x1-x)x + (y1-y)y equals
      // rho (R - rho), so u = (z x/rho, z y/rho, R - rho) / (4 pi dist^3), dist the distance to the
      // closest circle point. The core radius softens dist near the filament; W decays with dist.
      const double rho = std::hypot(p.x(), p.y());
      const double R = inst.ringRadius;
      const double dist2 = (rho - R) * (rho - R) + p.z() * p.z();
      const double soft = dist2 + inst.coreRadius * inst.coreRadius;
      const double denom = 4.0 * std::numbers::pi * soft * std::sqrt(soft);
      const Vec3 radial = rho > 0.0 ? Vec3(p.x() / rho, p.y() / rho, 0.0) : Vec3::Zero();
      return decay(std::sqrt(dist2), h) * (p.z() * radial + Vec3(0.0, 0.0, R - rho)) / denom;
    }
  }
  return Vec3::Zero();
}

Vec3 MotionField::velocity(const Vec3& x) const {
  Vec3 u = Vec3::Zero();
  for (const Compiled& c : compiled_) {
    const Vec3 local = c.inverseLinear * (x - c.instance.position);
    u += c.instance.magnitude * (c.rotation * primitive(c.instance, local));
  }
  return u;
}

const std::vector<std::string>& motionPrimitiveNames() {
  static const std::vector<std::string> names = {"uniform", "directional", "radial",     "cone",
                                                 "source",  "line_vortex", "ring_vortex"};
  return names;
}

MotionPrimitive parseMotionPrimitive(const std::string& name) {
  const auto& names = motionPrimitiveNames();
  for (std::size_t i = 0; i < names.size(); ++i)
    if (names[i] == name) return static_cast<MotionPrimitive>(i);
  throw std::invalid_argument("unknown motion field type '" + name + "'");
}

}  // namespace msim::fluid
