// Opaque surfaces in the volume renderer against closed forms:
//  - a sphere given as a signed-distance grid, lit by a directional light: Lambert's law
//    L = a E cos(theta) / pi + a I_sky on the lit side, only the sky a I_sky on the far side;
//  - the same sphere as a triangle mesh (through the BVH) and as a one-point PointSet;
//  - a ball behind a slab of absorbing smoke is dimmed by exactly exp(-sigma_t rho d) (eq. 5.6,
//    the surface radiance taking I_background's place in eq. 5.8);
//  - the ball's shadow in a homogeneous medium: the light grid is 0 behind it, unchanged beside it;
//  - a camera inside a solid is refused with a message.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include "expect_invalid.hpp"
#include "pixel.hpp"
#include "msim/render/frame_renderer.hpp"
#include "msim/render/volume_renderer.hpp"

using namespace msim;
using namespace msim::render;
using msim::render::test::pixel;

namespace {

constexpr int kN = 64;                 // cells per side of the unit box
const Vec3 kCentre(0.5, 0.5, 0.5);
constexpr double kRadius = 0.25;       // 16 cells
const Vec3 kToLight = Vec3(1.0, 0.5, 1.0).normalized();
constexpr double kIrradiance = 2.0;
const Vec3 kAlbedo(0.7, 0.5, 0.3);
const Vec3 kSky(0.05, 0.05, 0.05);

GridSpec<3> unitBox() { return GridSpec<3>(Vec3::Zero(), 1.0 / kN, IVec3::Constant(kN)); }

Grid<float, 3> sphereDistance() {
  Grid<float, 3> d(unitBox());
  for (std::size_t i = 0; i < d.count(); ++i)
    d[i] = static_cast<float>((d.position(d.coord(i)) - kCentre).norm() - kRadius);
  return d;
}

TriangleMesh uvSphere(int segments, int rings) {
  TriangleMesh m;
  for (int r = 0; r <= rings; ++r) {
    const double theta = std::numbers::pi * r / rings;
    for (int s = 0; s < segments; ++s) {
      const double phi = 2.0 * std::numbers::pi * s / segments;
      m.vertices.push_back(kCentre + kRadius * Vec3(std::sin(theta) * std::cos(phi), std::cos(theta),
                                                    std::sin(theta) * std::sin(phi)));
    }
  }
  const auto v = [&](int r, int s) { return r * segments + (s % segments); };
  for (int r = 0; r < rings; ++r)
    for (int s = 0; s < segments; ++s) {
      if (r > 0) m.triangles.push_back({v(r, s), v(r + 1, s), v(r, s + 1)});
      if (r < rings - 1) m.triangles.push_back({v(r, s + 1), v(r + 1, s), v(r + 1, s + 1)});
    }
  return m;
}

Light sun(const Vec3& toLight, double intensity) {
  Light l;
  l.type = Light::Type::Directional;
  l.direction = -toLight;
  l.intensity = intensity;
  return l;
}

Camera frontCamera() {
  Camera c;
  c.position = Vec3(0.5, 0.5, 3.0);
  c.target = kCentre;
  c.fovDegrees = 13.0;
  c.width = c.height = 64;
  return c;
}

VolumeRenderSettings surfaceSettings() {
  VolumeRenderSettings s;
  s.background = Vec3::Zero();
  s.ambient = kSky;
  s.surfaceAlbedo = kAlbedo;
  s.meshAlbedo = kAlbedo;
  return s;
}

// Where the pixel's ray meets the exact sphere: unit normal, and the ray direction.
bool exactHit(const CameraRays& rays, int x, int y, Vec3& normal, Vec3& dir) {
  const Ray r = rays.ray(x + 0.5, y + 0.5);
  const Vec3 oc = r.origin - kCentre;
  const double b = oc.dot(r.direction), disc = b * b - (oc.squaredNorm() - kRadius * kRadius);
  if (disc < 0.0) return false;
  normal = (r.origin + (-b - std::sqrt(disc)) * r.direction - kCentre).normalized();
  dir = r.direction;
  return true;
}

struct LambertError {
  double litWorst = 0.0, farWorst = 0.0;
  int lit = 0, far = 0;
};

// Pixels seen at least 17 degrees off the silhouette, and not within 12 degrees of the terminator.
LambertError compareWithLambert(const FloatImage& image, const Camera& camera) {
  const CameraRays rays(camera);
  LambertError e;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      Vec3 n, d;
      if (!exactHit(rays, x, y, n, d) || n.dot(-d) < 0.3) continue;
      const double c = n.dot(kToLight);
      const Vec3 got = pixel(image, x, y);
      if (c > 0.2) {
        const Vec3 expected = kAlbedo.cwiseProduct(kSky) + kAlbedo * (kIrradiance * c / std::numbers::pi);
        e.litWorst = std::max(e.litWorst, (got.cwiseQuotient(expected) - Vec3::Ones()).cwiseAbs().maxCoeff());
        ++e.lit;
      } else if (c < -0.2) {
        e.farWorst = std::max(e.farWorst, (got.cwiseQuotient(kAlbedo.cwiseProduct(kSky)) - Vec3::Ones()).cwiseAbs().maxCoeff());
        ++e.far;
      }
    }
  return e;
}

}  // namespace

TEST(Surfaces, DistanceGridSphereIsLambertian) {
  const Grid<float, 3> rho(unitBox());
  const Grid<float, 3> sdf = sphereDistance();
  VolumeInput input{&rho};
  input.surfaceDistance = &sdf;
  const Camera camera = frontCamera();
  const RenderResult r = renderVolume(input, camera, {sun(kToLight, kIrradiance)}, Medium(), surfaceSettings());
  const LambertError e = compareWithLambert(r.radiance, camera);
  std::printf("SDF sphere: %d lit pixels worst %.2e, %d far-side pixels worst %.2e, %lld surface hits\n", e.lit,
              e.litWorst, e.far, e.farWorst, r.stats.surfaceHits);
  EXPECT_GT(e.lit, 200);
  EXPECT_GT(e.far, 50);
  EXPECT_LT(e.litWorst, 0.02);
  EXPECT_LT(e.farWorst, 1e-5);
  EXPECT_EQ(pixel(r.radiance, 0, 0), Vec3::Zero());  // a corner ray misses the ball: background
}

TEST(Surfaces, MeshAndPointSphereMatchTheDistanceSphere) {
  const Grid<float, 3> rho(unitBox());
  const Grid<float, 3> sdf = sphereDistance();
  const TriangleMesh mesh = uvSphere(128, 64);
  const std::vector<Vecf<3>> centre = {kCentre.cast<float>()};
  const std::vector<Vecf<3>> colour = {kAlbedo.cast<float>()};
  const Camera camera = frontCamera();
  const std::vector<Light> lights = {sun(kToLight, kIrradiance)};

  VolumeInput bySdf{&rho}, byMesh{&rho}, byPoint{&rho};
  bySdf.surfaceDistance = &sdf;
  byMesh.meshes = {&mesh};
  PointSet ball;
  ball.positions = &centre;
  ball.radius = kRadius;
  ball.colours = &colour;
  byPoint.points = {ball};
  const RenderResult a = renderVolume(bySdf, camera, lights, Medium(), surfaceSettings());
  const RenderResult b = renderVolume(byMesh, camera, lights, Medium(), surfaceSettings());
  const RenderResult c = renderVolume(byPoint, camera, lights, Medium(), surfaceSettings());

  double sum = 0.0, diffMesh = 0.0, diffPoint = 0.0;
  for (std::size_t i = 0; i < a.radiance.rgb.size(); ++i) {
    sum += a.radiance.rgb[i];
    diffMesh += std::abs(b.radiance.rgb[i] - a.radiance.rgb[i]);
    diffPoint += std::abs(c.radiance.rgb[i] - a.radiance.rgb[i]);
  }
  const LambertError meshError = compareWithLambert(b.radiance, camera);
  const LambertError pointError = compareWithLambert(c.radiance, camera);
  std::printf("mesh (%zu triangles) vs SDF: mean |difference| %.2e of the mean; Lambert worst lit %.2e far %.2e\n",
              mesh.triangles.size(), diffMesh / sum, meshError.litWorst, meshError.farWorst);
  std::printf("point sphere vs SDF: mean |difference| %.2e of the mean; Lambert worst lit %.2e far %.2e\n",
              diffPoint / sum, pointError.litWorst, pointError.farWorst);
  EXPECT_LT(diffMesh / sum, 0.03);
  EXPECT_LT(diffPoint / sum, 0.03);
  EXPECT_LT(meshError.litWorst, 0.02);
  EXPECT_LT(pointError.litWorst, 0.02);
  EXPECT_LT(meshError.farWorst, 1e-5);
  EXPECT_LT(pointError.farWorst, 1e-5);
}

TEST(Surfaces, MeshLyingOnASampledSolidIsDrawnInFrontOfIt) {
  // A mesh on the sphere's surface (its vertices on it, as a cloth resting on a body) and the
  // same sphere as a distance grid, in different colours: the mesh is exact, the grid's trilinear
  // surface is good to a fraction of a cell, so wherever the two meet the mesh shows, not the
  // grid's solid poking through it (only at grazing angles near the outline, where the mesh's
  // chords lie more than a quarter cell behind the sampled surface along the ray: 1.0% of the
  // ball; 98% without the mesh's precedence).
  const Grid<float, 3> rho(unitBox());
  const Grid<float, 3> sdf = sphereDistance();
  const TriangleMesh mesh = uvSphere(48, 24);
  VolumeInput input{&rho};
  input.surfaceDistance = &sdf;
  input.meshes = {&mesh};
  VolumeRenderSettings settings = surfaceSettings();
  settings.surfaceAlbedo = Vec3(0.1, 0.1, 0.9);
  settings.meshAlbedo = Vec3(0.9, 0.1, 0.1);
  const Camera camera = frontCamera();
  const RenderResult r = renderVolume(input, camera, {sun(kToLight, kIrradiance)}, Medium(), settings);
  int ball = 0, solidShowing = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      const Vec3 v = pixel(r.radiance, x, y);
      if (v.maxCoeff() <= 0.0) continue;  // background
      ++ball;
      if (v.z() > v.x()) ++solidShowing;
    }
  EXPECT_GT(ball, 500);
  EXPECT_LT(solidShowing, 0.02 * ball);
  RecordProperty("solid_showing_fraction", std::to_string(double(solidShowing) / ball));
}

TEST(Surfaces, BallBehindSmokeIsDimmedByBeerLambert) {
  Grid<float, 3> rho(unitBox());
  constexpr double rho0 = 0.2;
  constexpr int first = 55, last = 60;  // a slab of 6 cells between the ball (z < 0.75) and the camera
  for (std::size_t i = 0; i < rho.count(); ++i) {
    const int k = rho.coord(i)[2];
    rho[i] = k >= first && k <= last ? static_cast<float>(rho0) : 0.0f;
  }
  const Grid<float, 3> empty(unitBox());
  const Grid<float, 3> sdf = sphereDistance();
  Medium absorbing;
  absorbing.extinction = 10.0;
  absorbing.albedo = 0.0;
  const Camera camera = frontCamera();
  // Light from the side: its paths to the ball stay below the slab.
  const std::vector<Light> lights = {sun(Vec3(1.0, 0.2, 0.0).normalized(), kIrradiance)};
  VolumeInput clear{&empty}, smoky{&rho};
  clear.surfaceDistance = smoky.surfaceDistance = &sdf;
  const RenderResult a = renderVolume(clear, camera, lights, absorbing, surfaceSettings());
  const RenderResult b = renderVolume(smoky, camera, lights, absorbing, surfaceSettings());
  const CameraRays rays(camera);
  const double depth = absorbing.extinction * rho0 * (last - first + 1) / static_cast<double>(kN);
  double worst = 0.0;
  int count = 0;
  for (int y = 0; y < camera.height; ++y)
    for (int x = 0; x < camera.width; ++x) {
      Vec3 n, d;
      if (!exactHit(rays, x, y, n, d) || n.dot(-d) < 0.3) continue;
      const double expected = std::exp(-depth / std::abs(d.z()));  // slant path through the slab
      const double got = pixel(b.radiance, x, y)[0] / pixel(a.radiance, x, y)[0];
      worst = std::max(worst, std::abs(got / expected - 1.0));
      ++count;
    }
  std::printf("ball behind a slab (tau %.4f): %d pixels, worst relative error %.2e\n", depth, count, worst);
  EXPECT_GT(count, 500);
  EXPECT_LT(worst, 2e-3);
}

TEST(Surfaces, BallShadowsTheMediumInTheLightGrid) {
  const Grid<float, 3> rho(unitBox(), 0.5f);
  const Grid<float, 3> sdf = sphereDistance();
  Medium m;
  m.extinction = 2.0;
  const double dx = 1.0 / kN;
  for (const Vec3& toLight : {Vec3(Vec3::UnitY()), Vec3(Vec3(0.3, 1.0, 0.2).normalized())}) {
    const Light light = sun(toLight, 1.0);
    const Grid<float, 3> plain = lightTransmittance(rho, light, m, 0.5);
    const Grid<float, 3> shadowed = lightTransmittance(rho, light, m, 0.5, &sdf);
    double worstInside = 0.0, worstBeside = 0.0;
    int inside = 0, beside = 0;
    for (std::size_t i = 0; i < rho.count(); ++i) {
      const Vec3 x = rho.position(rho.coord(i));
      const double along = (kCentre - x).dot(toLight);  // > 0: the ball lies towards the light
      const double miss = (kCentre - x - along * toLight).norm();  // closest approach of the path
      if (along > kRadius && miss < kRadius - 3.0 * dx) {
        worstInside = std::max(worstInside, static_cast<double>(shadowed[i]));
        ++inside;
      } else if ((along < -kRadius - 2.0 * dx || miss > kRadius + 3.0 * dx)) {
        worstBeside = std::max(worstBeside, std::abs(static_cast<double>(shadowed[i] - plain[i])));
        ++beside;
      }
    }
    std::printf("ball shadow, light towards (%.2f %.2f %.2f): %d cells behind it, largest T %.2e; %d cells clear of "
                "it, largest change %.2e\n",
                toLight.x(), toLight.y(), toLight.z(), inside, worstInside, beside, worstBeside);
    EXPECT_GT(inside, 1000);
    if (toLight == Vec3::UnitY()) {
      EXPECT_EQ(worstInside, 0.0);  // exactly no light: the sweep copies the solid's zero down
      EXPECT_LT(worstBeside, 1e-6);
    } else {
      EXPECT_LT(worstInside, 1e-3);
      EXPECT_LT(worstBeside, 0.02);
    }
  }
  // A point light's shadow rays are blocked the same way.
  Light bulb;
  bulb.type = Light::Type::Point;
  bulb.position = Vec3(0.5, 0.95, 0.5);
  const Grid<float, 3> T = lightTransmittance(rho, bulb, m, 0.5, &sdf);
  EXPECT_EQ(T(IVec3(32, 10, 32)), 0.0f);  // below the ball
  EXPECT_GT(T(IVec3(2, 10, 2)), 0.0f);    // off to the side
}

TEST(Surfaces, CameraInsideASolidIsRefused) {
  const Grid<float, 3> rho(unitBox());
  const Grid<float, 3> sdf = sphereDistance();
  const TriangleMesh mesh = uvSphere(32, 16);
  Camera inside = frontCamera();
  inside.position = Vec3(0.5, 0.5, 0.4);
  inside.target = Vec3(0.5, 0.5, 0.0);
  VolumeInput bySdf{&rho}, byMesh{&rho};
  bySdf.surfaceDistance = &sdf;
  byMesh.meshes = {&mesh};
  const std::vector<Light> lights = {sun(kToLight, 1.0)};
  expectInvalidArgument([&] { renderVolume(bySdf, inside, lights, Medium(), surfaceSettings()); },
                        "camera is inside an obstacle (signed distance -0.15 m at the camera position)");
  expectInvalidArgument([&] { renderVolume(byMesh, inside, lights, Medium(), surfaceSettings()); },
                        "camera is inside mesh 0 (a ray from the camera crosses it 1 times)");
  FrameRenderConfig config;
  config.camera = inside;
  FrameSurfaces surfaces;
  surfaces.distance = &sdf;
  expectInvalidArgument([&] { renderFrame(config, rho, nullptr, nullptr, surfaces); }, "camera is inside an obstacle");
  // Outside the box there are no obstacles; outside the mesh nothing is refused.
  EXPECT_TRUE(std::isinf(signedDistanceAt(sdf, Vec3(2.0, 0.5, 0.5))));
  EXPECT_NEAR(signedDistanceAt(sdf, Vec3(0.5, 0.5, 0.4)), -0.15, 1e-3);
  EXPECT_NO_THROW(checkCameraOutsideSolids(frontCamera().position, &sdf, {&mesh}));
}

TEST(Surfaces, BadInputsAreRefused) {
  const Grid<float, 3> rho(unitBox());
  const Grid<float, 3> small(GridSpec<3>(Vec3::Zero(), 1.0 / 32, IVec3::Constant(32)));
  VolumeInput input{&rho};
  input.surfaceDistance = &small;
  expectInvalidArgument([&] { input.validate(); }, "surface distance");
  TriangleMesh broken;
  broken.vertices = {Vec3::Zero(), Vec3::UnitX()};
  broken.triangles = {{0, 1, 2}};
  expectInvalidArgument([&] { SurfaceScene({&broken}, {}, Vec3::Constant(0.5)); }, "vertex index 2");
  PointSet noRadius;
  const std::vector<Vecf<3>> one = {Vecf<3>::Zero()};
  noRadius.positions = &one;
  expectInvalidArgument([&] { SurfaceScene({}, {noRadius}, Vec3::Constant(0.5)); }, "radius");
  VolumeRenderSettings s;
  s.surfaceAlbedo = Vec3(1.2, 0.5, 0.5);
  expectInvalidArgument([&] { s.validate(); }, "surfaceAlbedo");
  s.surfaceAlbedo = Vec3::Constant(0.5);
  s.meshAlbedo = Vec3(0.5, -0.1, 0.5);
  expectInvalidArgument([&] { s.validate(); }, "meshAlbedo");
}
