#pragma once
// Pinhole camera for the volume renderer (Stam ch. 5 renders with an ordinary perspective camera;
// nothing in the transport depends on it). Image pixel (x, y) counts from the top-left corner, y
// down, as io::Image stores rows; the centre of pixel (i, j) is at (i + 0.5, j + 0.5).
#include <optional>

#include "msim/core/vec.hpp"

namespace msim::render {

struct Camera {
  Vec3 position = Vec3(0.0, 0.0, 5.0);
  Vec3 target = Vec3::Zero();
  Vec3 up = Vec3::UnitY();  // image up; need not be orthogonal to the view direction
  double fovDegrees = 40.0;  // vertical field of view (top to bottom edge of the image)
  int width = 640, height = 480;

  // std::invalid_argument naming the bad value: fov outside (0, 180), a size that is not positive,
  // position == target, up parallel to the view direction, or a non-finite vector.
  void validate() const;
};

struct Ray {
  Vec3 origin;
  Vec3 direction;  // unit length
};

// Parameter interval [t0, t1] of a ray inside the box [lo, hi], t0 >= 0 (slab method); false if
// it misses.
bool intersectBox(const Ray& r, const Vec3& lo, const Vec3& hi, double& t0, double& t1);

// The view basis of a validated camera, computed once: primary rays and the inverse projection.
class CameraRays {
 public:
  explicit CameraRays(const Camera& camera);  // validates the camera

  // Ray through the continuous image point (px, py), px in [0, width], py in [0, height] from the
  // top; ray(width / 2, height / 2) passes through the target.
  Ray ray(double px, double py) const {
    const Vec3 d = forward_ + (px - halfWidth_) * pixelScale_ * right_ - (py - halfHeight_) * pixelScale_ * up_;
    return {origin_, d.normalized()};
  }
  // Continuous image point of world point x; nullopt when x is not in front of the camera.
  std::optional<Vec2> project(const Vec3& x) const;

  const Vec3& forward() const { return forward_; }
  const Vec3& right() const { return right_; }
  const Vec3& up() const { return up_; }

 private:
  Vec3 origin_, forward_, right_, up_;
  double halfWidth_, halfHeight_;
  double pixelScale_;  // image-plane size of one pixel at unit distance along forward
};

// A camera that frames the box [lo, hi] (a grid's domain): it looks at the box centre along
// -viewAxis (by default (upAxis + 1) % 3: along -z for the default y-up), image up along +upAxis,
// from the distance at which the near face of the box fills the image less a 10% border in the
// tighter of the two directions (so all 8 corners are in view). std::invalid_argument for an axis
// outside 0..2, a view axis equal to the up axis, an empty box or a size that is not positive.
Camera frameBox(const Vec3& lo, const Vec3& hi, int width, int height, int upAxis = 1, int viewAxis = -1);

}  // namespace msim::render
