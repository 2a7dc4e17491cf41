// Pinhole camera: the image centre looks at the target, projection inverts ray generation, the
// field of view spans the image height, frameBox keeps a box in view, bad cameras are refused.
#include <gtest/gtest.h>

#include <cmath>
#include <numbers>
#include <stdexcept>

#include "expect_invalid.hpp"
#include "msim/render/camera.hpp"

using namespace msim;
using namespace msim::render;

namespace {

Camera camera(const Vec3& position, const Vec3& target, const Vec3& up, int width, int height) {
  Camera c;
  c.position = position;
  c.target = target;
  c.up = up;
  c.width = width;
  c.height = height;
  return c;
}

}  // namespace

TEST(Camera, RayThroughTheImageCentreHitsTheTarget) {
  for (const Camera& c : {camera(Vec3(0, 0, 5), Vec3::Zero(), Vec3::UnitY(), 640, 480),
                          camera(Vec3(3, -2, 1), Vec3(0.5, 0.2, -0.7), Vec3(0.3, 1, 0.2), 101, 37),
                          camera(Vec3(-1, 4, 2), Vec3(1, 0, 0), Vec3::UnitZ(), 64, 128)}) {
    const Ray r = CameraRays(c).ray(0.5 * c.width, 0.5 * c.height);
    EXPECT_NEAR(r.direction.norm(), 1.0, 1e-14);
    EXPECT_LT((r.origin - c.position).norm(), 1e-14);
    const Vec3 toTarget = c.target - c.position;
    // Distance of the target from the ray's line.
    EXPECT_LT((toTarget - toTarget.dot(r.direction) * r.direction).norm(), 1e-12);
    EXPECT_GT(toTarget.dot(r.direction), 0.0);
  }
}

TEST(Camera, ProjectionInvertsRayGenerationAndImageAxesPointRightAndUp) {
  const Camera c = camera(Vec3(3, -2, 1), Vec3(0.5, 0.2, -0.7), Vec3(0.3, 1, 0.2), 101, 37);
  const CameraRays rays(c);
  for (const Vec2& p : {Vec2(0, 0), Vec2(101, 37), Vec2(12.25, 30.5), Vec2(80, 3)}) {
    const Ray r = rays.ray(p.x(), p.y());
    const auto q = rays.project(r.origin + 2.7 * r.direction);
    ASSERT_TRUE(q.has_value());
    EXPECT_NEAR(q->x(), p.x(), 1e-9);
    EXPECT_NEAR(q->y(), p.y(), 1e-9);
  }
  EXPECT_FALSE(rays.project(c.position - (c.target - c.position)).has_value());  // behind the camera
  // Pixel x grows to the camera's right, pixel y grows downwards (against up).
  EXPECT_GT(rays.ray(100, 18.5).direction.dot(rays.right()), 0.0);
  EXPECT_GT(rays.ray(50.5, 0).direction.dot(rays.up()), 0.0);
  EXPECT_GT(rays.up().dot(c.up), 0.0);
}

TEST(Camera, VerticalFieldOfViewSpansTheImageHeight) {
  Camera c = camera(Vec3(0, 0, 5), Vec3::Zero(), Vec3::UnitY(), 300, 200);
  c.fovDegrees = 60.0;
  const CameraRays rays(c);
  const Vec3 top = rays.ray(150, 0).direction, bottom = rays.ray(150, 200).direction;
  EXPECT_NEAR(std::acos(top.dot(bottom)) * 180.0 / std::numbers::pi, 60.0, 1e-9);
  EXPECT_GT(top.y(), 0.0);
}

TEST(Camera, FrameBoxSeesAllEightCornersAndFillsTheImage) {
  struct Case {
    Vec3 lo, hi;
    int width, height, upAxis, viewAxis = -1;
  };
  for (const Case& k : {Case{Vec3::Zero(), Vec3::Ones(), 640, 480, 1}, Case{Vec3(-1, 0, 2), Vec3(3, 1, 2.5), 640, 480, 1},
                        Case{Vec3::Zero(), Vec3(0.5, 2, 1), 200, 400, 1}, Case{Vec3::Zero(), Vec3(1, 2, 3), 320, 240, 2},
                        Case{Vec3(-2, -2, -2), Vec3(2, 0, 1), 100, 100, 0}, Case{Vec3::Zero(), Vec3(2, 1, 1.5), 640, 480, 2, 1},
                        Case{Vec3(-1, 0, -1), Vec3(1, 1, 1), 320, 240, 1, 0}}) {
    const Camera c = frameBox(k.lo, k.hi, k.width, k.height, k.upAxis, k.viewAxis);
    if (k.viewAxis >= 0) {  // looking along -viewAxis
      EXPECT_LT((CameraRays(c).forward() + Vec3::Unit(k.viewAxis)).norm(), 1e-12);
    }
    EXPECT_EQ(c.width, k.width);
    EXPECT_EQ(c.up, Vec3::Unit(k.upAxis));
    const CameraRays rays(c);
    double fillX = 0.0, fillY = 0.0;  // largest distance of a corner from the image centre, as a fraction of the half-size
    for (int corner = 0; corner < 8; ++corner) {
      const Vec3 x((corner & 1) ? k.hi.x() : k.lo.x(), (corner & 2) ? k.hi.y() : k.lo.y(), (corner & 4) ? k.hi.z() : k.lo.z());
      const auto p = rays.project(x);
      ASSERT_TRUE(p.has_value());
      EXPECT_GE(p->x(), 0.0);
      EXPECT_LE(p->x(), k.width);
      EXPECT_GE(p->y(), 0.0);
      EXPECT_LE(p->y(), k.height);
      fillX = std::max(fillX, std::abs(p->x() - 0.5 * k.width) / (0.5 * k.width));
      fillY = std::max(fillY, std::abs(p->y() - 0.5 * k.height) / (0.5 * k.height));
    }
    EXPECT_NEAR(std::max(fillX, fillY), 0.9, 1e-9);  // the documented 10% border in the tighter direction
  }
  const Camera c = frameBox(Vec3::Zero(), Vec3::Ones(), 640, 480);
  EXPECT_LT((CameraRays(c).forward() - Vec3(0, 0, -1)).norm(), 1e-12);  // looking along -z
}

TEST(Camera, FrameBoxRefusesAViewAlongTheUpAxis) {
  EXPECT_THROW(frameBox(Vec3::Zero(), Vec3::Ones(), 64, 64, 1, 1), std::invalid_argument);
  EXPECT_THROW(frameBox(Vec3::Zero(), Vec3::Ones(), 64, 64, 1, 3), std::invalid_argument);
}

TEST(Camera, InvalidCamerasThrowWithAMessage) {
  const Camera good = camera(Vec3(0, 0, 5), Vec3::Zero(), Vec3::UnitY(), 64, 48);
  EXPECT_NO_THROW(good.validate());
  for (double fov : {0.0, -10.0, 180.0, 200.0, std::nan("")}) {
    Camera c = good;
    c.fovDegrees = fov;
    expectInvalidArgument([&] { c.validate(); }, "fovDegrees");
    expectInvalidArgument([&] { CameraRays{c}; }, "fovDegrees");
  }
  for (const auto& [w, h] : {std::pair{0, 48}, std::pair{64, 0}, std::pair{-3, 10}}) {
    Camera c = good;
    c.width = w;
    c.height = h;
    expectInvalidArgument([&] { c.validate(); }, "image size");
  }
  Camera same = good;
  same.target = same.position;
  expectInvalidArgument([&] { same.validate(); }, "position equals target");
  Camera parallel = good;
  parallel.up = Vec3(0, 0, -2);
  expectInvalidArgument([&] { parallel.validate(); }, "parallel");
  Camera zeroUp = good;
  zeroUp.up = Vec3::Zero();
  expectInvalidArgument([&] { zeroUp.validate(); }, "up");
  expectInvalidArgument([] { frameBox(Vec3::Zero(), Vec3::Ones(), 64, 48, 3); }, "upAxis");
  expectInvalidArgument([] { frameBox(Vec3::Ones(), Vec3::Zero(), 64, 48); }, "empty");
  expectInvalidArgument([] { frameBox(Vec3::Zero(), Vec3::Ones(), 0, 48); }, "image size");
}
