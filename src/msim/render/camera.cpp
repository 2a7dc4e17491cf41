#include "msim/render/camera.hpp"

#include <algorithm>
#include <cmath>
#include <limits>
#include <numbers>
#include <stdexcept>
#include <string>

#include <Eigen/Geometry>  // cross product

namespace msim::render {

namespace {

std::string str(const Vec3& v) {
  return "(" + std::to_string(v[0]) + ", " + std::to_string(v[1]) + ", " + std::to_string(v[2]) + ")";
}

double tanHalfFov(double fovDegrees) { return std::tan(0.5 * fovDegrees * std::numbers::pi / 180.0); }

}  // namespace

void Camera::validate() const {
  if (!position.allFinite() || !target.allFinite() || !up.allFinite())
    throw std::invalid_argument("camera: position, target and up must be finite (position " + str(position) +
                                ", target " + str(target) + ", up " + str(up) + ")");
  if (!(fovDegrees > 0.0 && fovDegrees < 180.0))
    throw std::invalid_argument("camera: fovDegrees must be in (0, 180), got " + std::to_string(fovDegrees));
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("camera: image size must be positive, got " + std::to_string(width) + " x " +
                                std::to_string(height));
  const Vec3 view = target - position;
  if (!(view.norm() > 0.0)) throw std::invalid_argument("camera: position equals target " + str(target));
  // The image basis needs a component of `up` orthogonal to the view direction.
  if (!(view.normalized().cross(up).norm() > 1e-9 * up.norm()))
    throw std::invalid_argument("camera: up " + str(up) + " is zero or parallel to the view direction " +
                                str(view.normalized()));
}

CameraRays::CameraRays(const Camera& camera) {
  camera.validate();
  origin_ = camera.position;
  forward_ = (camera.target - camera.position).normalized();
  right_ = forward_.cross(camera.up).normalized();
  up_ = right_.cross(forward_);
  halfWidth_ = 0.5 * camera.width;
  halfHeight_ = 0.5 * camera.height;
  pixelScale_ = tanHalfFov(camera.fovDegrees) / halfHeight_;
}

std::optional<Vec2> CameraRays::project(const Vec3& x) const {
  const Vec3 d = x - origin_;
  const double depth = d.dot(forward_);
  if (!(depth > 0.0)) return std::nullopt;
  return Vec2(halfWidth_ + d.dot(right_) / (depth * pixelScale_), halfHeight_ - d.dot(up_) / (depth * pixelScale_));
}

Camera frameBox(const Vec3& lo, const Vec3& hi, int width, int height, int upAxis, int viewAxis) {
  if (upAxis < 0 || upAxis > 2) throw std::invalid_argument("frameBox: upAxis must be 0, 1 or 2, got " + std::to_string(upAxis));
  if (viewAxis < 0) viewAxis = (upAxis + 1) % 3;
  if (viewAxis > 2 || viewAxis == upAxis)
    throw std::invalid_argument("frameBox: viewAxis must be 0, 1 or 2 and differ from upAxis, got " +
                                std::to_string(viewAxis));
  if (!lo.allFinite() || !hi.allFinite() || !(lo.array() < hi.array()).all())
    throw std::invalid_argument("frameBox: empty or non-finite box " + str(lo) + " .. " + str(hi));
  if (width <= 0 || height <= 0)
    throw std::invalid_argument("frameBox: image size must be positive, got " + std::to_string(width) + " x " +
                                std::to_string(height));
  const int rightAxis = 3 - upAxis - viewAxis;  // the image's horizontal
  Camera c;
  c.width = width;
  c.height = height;
  const Vec3 centre = 0.5 * (lo + hi);
  const Vec3 half = 0.5 * (hi - lo);
  c.up = Vec3::Unit(upAxis);
  c.target = centre;
  // The near face is the largest in the image: its half-extents must subtend at most 90% of the
  // half-image in both directions.
  const double tanV = tanHalfFov(c.fovDegrees);
  const double tanH = tanV * width / height;
  const double nearDistance = std::max(half[upAxis] / tanV, half[rightAxis] / tanH) / 0.9;
  c.position = centre + (half[viewAxis] + nearDistance) * Vec3::Unit(viewAxis);
  return c;
}

bool intersectBox(const Ray& r, const Vec3& lo, const Vec3& hi, double& t0, double& t1) {
  t0 = 0.0;
  t1 = std::numeric_limits<double>::infinity();
  for (int a = 0; a < 3; ++a) {
    if (r.direction[a] == 0.0) {
      if (r.origin[a] < lo[a] || r.origin[a] > hi[a]) return false;
      continue;
    }
    const double inv = 1.0 / r.direction[a];
    double ta = (lo[a] - r.origin[a]) * inv, tb = (hi[a] - r.origin[a]) * inv;
    if (ta > tb) std::swap(ta, tb);
    t0 = std::max(t0, ta);
    t1 = std::min(t1, tb);
  }
  return t0 < t1;
}

}  // namespace msim::render
