// The liquid renderer against closed forms:
//  - Fresnel's equations (dielectric.hpp): ((n1 - n2) / (n1 + n2))^2 at normal incidence, R -> 1 at
//    grazing incidence, total internal reflection beyond asin(1 / n), R + T = 1 with T from the
//    transmission amplitudes (an independent formula), Stokes' reciprocity; Snell's law for the
//    refracted direction;
//  - the level set's root on a plane (exact for a linear phi under trilinear interpolation);
//  - a slab of liquid: a ray through it keeps (1 - R_i)(1 - R_t) exp(-sigma d / cos theta_t) per
//    channel plus its internal reflections (a geometric series), normal and oblique;
//  - a sphere of liquid: a ray through the centre goes on undeflected, one off the centre does not;
//  - the light reaching a point under the slab, and bad optics refused with the key's name.
#include <gtest/gtest.h>

#include <cmath>
#include <cstdio>
#include <numbers>

#include <Eigen/Geometry>  // cross products

#include "expect_invalid.hpp"
#include "msim/render/dielectric.hpp"
#include "msim/render/liquid_tracer.hpp"

using namespace msim;
using namespace msim::render;

namespace {

constexpr double kWater = 1.33;
const Vec3 kAbsorption(2.0, 0.5, 0.1);  // [1/m], strong enough for the attenuation to matter

double radians(double degrees) { return degrees * std::numbers::pi / 180.0; }

// Fresnel transmittance from the transmission amplitudes (Hecht eq. 4.40-4.43 and 4.56-4.61): the
// transmitted power through unit area of the interface, T = (n2 cos_t / n1 cos_i) (t_s^2 + t_p^2) / 2.
double transmittanceFromAmplitudes(double cosI, double n1, double n2) {
  const double sinT = n1 / n2 * std::sqrt(1.0 - cosI * cosI);
  const double cosT = std::sqrt(1.0 - sinT * sinT);
  const double ts = 2.0 * n1 * cosI / (n1 * cosI + n2 * cosT);
  const double tp = 2.0 * n1 * cosI / (n2 * cosI + n1 * cosT);
  return n2 * cosT / (n1 * cosI) * 0.5 * (ts * ts + tp * tp);
}

// A liquid level set of a function of position, on a cube of n cells over the unit box.
template <typename F>
Grid<float, 3> levelSet(int n, F&& phi) {
  Grid<float, 3> g(GridSpec<3>(Vec3::Zero(), 1.0 / n, IVec3::Constant(n)));
  for (std::size_t i = 0; i < g.count(); ++i) g[i] = static_cast<float>(phi(g.position(g.coord(i))));
  return g;
}

// Liquid for 0.3 < y < 0.7, in a box 2 m long in x (so that oblique rays reflected to and fro
// inside stay in it) and 1 m in y and z, 32 cells per metre.
Grid<float, 3> slab() {
  Grid<float, 3> g(GridSpec<3>(Vec3::Zero(), 1.0 / 32, IVec3(64, 32, 32)));
  for (std::size_t i = 0; i < g.count(); ++i) {
    const double y = g.position(g.coord(i)).y();
    g[i] = static_cast<float>(std::max(0.3 - y, y - 0.7));
  }
  return g;
}

// Nothing but a sky that shines (radiance 1 per channel) only within `cone` of one direction.
class BeamScene final : public TracedScene {
 public:
  BeamScene(const Vec3& direction, double coneDegrees)
      : direction_(direction.normalized()), cosCone_(std::cos(radians(coneDegrees))) {}
  bool opaqueHit(const Ray&, double, SurfaceHit&) const override { return false; }
  Vec3 opaqueRadiance(const Vec3&, const SurfaceHit&) const override { return Vec3::Zero(); }
  Segment medium(const Ray&, double) const override { return {}; }
  Vec3 sky(const Vec3& d) const override { return d.dot(direction_) >= cosCone_ ? Vec3::Ones() : Vec3::Zero(); }

 private:
  Vec3 direction_;
  double cosCone_;
};

LiquidOptics optics() {
  LiquidOptics o;
  o.ior = kWater;
  o.absorption = kAbsorption;
  o.maxBounces = 8;
  return o;
}

}  // namespace

TEST(Fresnel, NormalIncidenceIsTheSquaredIndexRatio) {
  const double expected = std::pow((1.0 - kWater) / (1.0 + kWater), 2);  // 0.020059
  EXPECT_NEAR(fresnelReflectance(1.0, 1.0, kWater), expected, 1e-12);
  EXPECT_NEAR(fresnelReflectance(1.0, kWater, 1.0), expected, 1e-12);
  EXPECT_NEAR(fresnelReflectance(1.0, 1.0, kWater), 0.0200, 1e-4);
}

TEST(Fresnel, ReflectanceTendsToOneAtGrazingIncidence) {
  EXPECT_DOUBLE_EQ(fresnelReflectance(0.0, 1.0, kWater), 1.0);
  EXPECT_GT(fresnelReflectance(1e-4, 1.0, kWater), 0.999);
  EXPECT_GT(fresnelReflectance(std::cos(radians(89.0)), 1.0, kWater), 0.85);
  // Monotonic from the Brewster angle on (r_p = 0 there; below it R dips only slightly).
  double previous = fresnelReflectance(std::cos(radians(std::atan(kWater) * 180.0 / std::numbers::pi)), 1.0, kWater);
  for (double deg = 54.0; deg < 90.0; deg += 1.0) {
    const double r = fresnelReflectance(std::cos(radians(deg)), 1.0, kWater);
    EXPECT_GT(r, previous) << deg;
    previous = r;
  }
}

TEST(Fresnel, TotalInternalReflectionBeyondTheCriticalAngle) {
  const double critical = std::asin(1.0 / kWater);  // 48.75 degrees
  const Vec3 n = Vec3::UnitY();                     // the liquid below, the air above
  for (double offset : {1e-3, 0.05, 0.3}) {
    const double beyond = critical + offset, before = critical - offset;
    EXPECT_EQ(fresnelReflectance(std::cos(beyond), kWater, 1.0), 1.0);
    EXPECT_LT(fresnelReflectance(std::cos(before), kWater, 1.0), 1.0);
    EXPECT_FALSE(refract(Vec3(std::sin(beyond), std::cos(beyond), 0.0), n, kWater, 1.0).has_value());
    EXPECT_TRUE(refract(Vec3(std::sin(before), std::cos(before), 0.0), n, kWater, 1.0).has_value());
  }
  // From the air side there is no critical angle.
  EXPECT_LT(fresnelReflectance(std::cos(radians(80.0)), 1.0, kWater), 1.0);
}

TEST(Fresnel, ReflectanceAndTransmittanceSumToOne) {
  double worst = 0.0;
  for (double deg = 0.0; deg < 89.9; deg += 0.5) {
    const double c = std::cos(radians(deg));
    worst = std::max(worst, std::abs(fresnelReflectance(c, 1.0, kWater) + transmittanceFromAmplitudes(c, 1.0, kWater) - 1.0));
    if (deg < 48.0)  // inside, below the critical angle
      worst = std::max(worst, std::abs(fresnelReflectance(c, kWater, 1.0) + transmittanceFromAmplitudes(c, kWater, 1.0) - 1.0));
    // Stokes: the same reflectance seen from the other side at the refracted angle.
    const double sinT = std::sin(radians(deg)) / kWater, cosT = std::sqrt(1.0 - sinT * sinT);
    EXPECT_NEAR(fresnelReflectance(c, 1.0, kWater), fresnelReflectance(cosT, kWater, 1.0), 1e-12) << deg;
  }
  std::printf("R + T - 1: worst %.2e over 0-89.5 degrees, both sides\n", worst);
  EXPECT_LT(worst, 1e-12);
}

TEST(Snell, RefractedDirectionObeysSnellsLaw) {
  const Vec3 n = Vec3(0.2, 1.0, -0.3).normalized();
  for (double deg = 0.0; deg < 89.0; deg += 7.0) {
    // A direction at `deg` to -n, in a plane that is not a coordinate plane.
    const Vec3 tangent = n.cross(Vec3(1.0, 0.0, 0.0)).normalized();
    const Vec3 d = (-std::cos(radians(deg)) * n + std::sin(radians(deg)) * tangent).normalized();
    for (const auto& [n1, n2] : {std::pair{1.0, kWater}, std::pair{kWater, 1.0}}) {
      const auto t = refract(d, n, n1, n2);
      if (n1 > n2 && n1 * std::sin(radians(deg)) > n2) {
        EXPECT_FALSE(t.has_value());
        continue;
      }
      ASSERT_TRUE(t.has_value()) << deg;
      EXPECT_NEAR(t->norm(), 1.0, 1e-12);
      const double sinI = d.cross(n).norm(), sinT = t->cross(n).norm();
      EXPECT_NEAR(n1 * sinI, n2 * sinT, 1e-12) << deg;
      EXPECT_LT(t->dot(n), 0.0) << "the refracted ray goes on through the surface";
      EXPECT_NEAR(d.cross(n).dot(*t), 0.0, 1e-12) << "coplanar with the ray and the normal";
    }
  }
  // Reflection keeps the angle and flips the normal component.
  const Vec3 d = Vec3(1.0, -2.0, 0.5).normalized();
  EXPECT_NEAR(reflect(d, n).dot(n), -d.dot(n), 1e-12);
  EXPECT_NEAR((reflect(d, n) - d).cross(n).norm(), 0.0, 1e-12);
}

TEST(LiquidSurface, RootOnAPlaneWithinAThousandthOfACell) {
  // A tilted plane n . x = c: trilinear interpolation of a linear function is exact.
  const Vec3 n = Vec3(0.3, 1.0, 0.2).normalized();
  const double c = 0.4137;
  const Grid<float, 3> phi = levelSet(32, [&](const Vec3& x) { return n.dot(x) - c; });
  const LiquidSurface surface(phi);
  const double dx = surface.cellSize();
  double worst = 0.0;
  int rays = 0;
  for (double a = -0.6; a <= 0.6; a += 0.2)
    for (double b = -0.6; b <= 0.6; b += 0.3) {
      // Aimed at a point of the plane inside the box, from 0.6 m away (outside the box for most).
      const Vec3 dir = Vec3(a, -1.0, b).normalized();
      Vec3 onPlane(0.5 - 0.3 * a, 0.0, 0.5 - 0.3 * b);
      onPlane.y() = (c - n.x() * onPlane.x() - n.z() * onPlane.z()) / n.y();
      const Ray down{onPlane - 0.6 * dir, dir};
      double t;
      ASSERT_TRUE(surface.intersect(down, 0.0, 10.0, false, t));
      const double analytic = 0.6;
      worst = std::max(worst, std::abs(t - analytic) * std::abs(n.dot(down.direction)) / dx);  // distance to the plane
      // And back out from inside, upwards.
      const Ray up{down.origin + (analytic + 0.2) * down.direction, -down.direction};
      ASSERT_TRUE(surface.intersect(up, 0.0, 10.0, true, t));
      worst = std::max(worst, std::abs(t - 0.2) * std::abs(n.dot(down.direction)) / dx);
      rays += 2;
    }
  std::printf("plane root: worst %.2e cells over %d rays\n", worst, rays);
  EXPECT_LT(worst, 1e-3);
}

TEST(LiquidTracer, SlabAttenuatesByBeerLambertAndTwoFresnelTransmissions) {
  const Grid<float, 3> phi = slab();
  const LiquidSurface surface(phi);
  const LiquidTracer tracer(surface, optics());
  const double d = 0.4;
  for (double deg : {0.0, 30.0, 60.0}) {
    const double sinI = std::sin(radians(deg)), cosI = std::cos(radians(deg));
    const double cosT = std::sqrt(1.0 - sinI * sinI / (kWater * kWater));
    const Vec3 dir(sinI, -cosI, 0.0);
    // Meets the top of the slab at (0.2, 0.7, 0.5); its internal reflections stay clear of the box's sides.
    const Ray ray{Vec3(0.2, 0.7, 0.5) - (0.1 / cosI) * dir, dir};
    const Vec3 L = tracer.radiance(ray, BeamScene(dir, 0.01));
    const double R = fresnelReflectance(cosI, 1.0, kWater), Rin = fresnelReflectance(cosT, kWater, 1.0);
    const double path = d / cosT;
    for (int ch = 0; ch < 3; ++ch) {
      const double e = std::exp(-kAbsorption[ch] * path);
      const double twoTransmissions = (1.0 - R) * (1.0 - Rin) * e;
      // Light reflected back and forth inside leaves along the same direction: a geometric series.
      const double series = twoTransmissions / (1.0 - Rin * Rin * e * e);
      std::printf("slab %2.0f deg, channel %d: %.6f, analytic %.6f (first pass %.6f)\n", deg, ch, L[ch], series,
                  twoTransmissions);
      // Up to 30 degrees the internal reflections add less than 1e-3 (R ~ 0.02 at each face); at 60
      // degrees they add 0.3% of the light (R = 0.06 at the inner face) and only the series holds.
      if (deg <= 30.0) {
        EXPECT_NEAR(L[ch], twoTransmissions, 1e-3);
      }
      // New rays start 1e-4 cell off the surface, so each pass through the liquid is 2e-4 cell short:
      // a relative error of sigma_a * 2e-4 dx / cos theta_t (2.5e-5 in the red at 60 degrees).
      EXPECT_NEAR(L[ch], series, 2e-5);
    }
  }
}

TEST(LiquidTracer, RayThroughASphereCentreIsUndeflected) {
  const Vec3 centre = Vec3::Constant(0.5);
  const double r = 0.25;
  const Grid<float, 3> phi = levelSet(64, [&](const Vec3& x) { return (x - centre).norm() - r; });
  const LiquidSurface surface(phi);
  const LiquidTracer tracer(surface, optics());
  const Vec3 dir = Vec3(1.0, 0.0, 0.0);
  const BeamScene beam(dir, 0.05);  // only light within 0.05 degrees of the ray's direction
  const Vec3 through = tracer.radiance({Vec3(-0.5, 0.5, 0.5), dir}, beam);
  const double R = fresnelReflectance(1.0, 1.0, kWater);
  for (int ch = 0; ch < 3; ++ch) {
    const double e = std::exp(-kAbsorption[ch] * 2.0 * r);
    const double analytic = (1.0 - R) * (1.0 - R) * e / (1.0 - R * R * e * e);
    std::printf("sphere centre, channel %d: %.6f, analytic %.6f\n", ch, through[ch], analytic);
    // The trilinear sphere's chord is short by O(dx^2 / r): 1e-3 relative in the red here.
    EXPECT_NEAR(through[ch], analytic, 2e-3 * analytic);
  }
  // A quarter radius off the centre the ray bends away from the beam: (1 - R) x ... of the light is gone.
  const Vec3 off = tracer.radiance({Vec3(-0.5, 0.5 + 0.25 * r, 0.5), dir}, beam);
  EXPECT_LT(off.maxCoeff(), 1e-3);
}

TEST(LiquidTracer, LightUnderASlabIsDimmedByItsDepthAndOneCrossing) {
  const Grid<float, 3> phi = slab();
  const LiquidSurface surface(phi);
  const LiquidTracer tracer(surface, optics());
  const Vec3 toLight = Vec3(0.4, 1.0, 0.0).normalized();
  const Vec3 x(0.4, 0.35, 0.5);  // in the liquid, 0.35 below its top
  const Vec3 T = tracer.lightTransmittance(x, toLight, std::numeric_limits<double>::infinity());
  const double cosAir = toLight.y();
  for (int ch = 0; ch < 3; ++ch) {
    const double analytic = (1.0 - fresnelReflectance(cosAir, 1.0, kWater)) * std::exp(-kAbsorption[ch] * 0.35 / cosAir);
    EXPECT_NEAR(T[ch], analytic, 1e-6) << ch;
  }
  // Under the slab: both crossings and the full thickness.
  const Vec3 below = tracer.lightTransmittance(Vec3(0.4, 0.1, 0.5), Vec3::UnitY(), 10.0);
  const double R = fresnelReflectance(1.0, 1.0, kWater);
  EXPECT_NEAR(below[1], (1.0 - R) * (1.0 - R) * std::exp(-kAbsorption[1] * 0.4), 1e-6);
}

TEST(LiquidTracer, BadOpticsAreRefusedNamingTheValue) {
  const Grid<float, 3> phi = slab();
  const LiquidSurface surface(phi);
  LiquidOptics o = optics();
  o.ior = 1.0;
  expectInvalidArgument([&] { LiquidTracer(surface, o); }, "ior");
  o = optics();
  o.absorption = Vec3(0.1, -0.2, 0.1);
  expectInvalidArgument([&] { LiquidTracer(surface, o); }, "absorption");
  o = optics();
  o.maxBounces = 0;
  expectInvalidArgument([&] { LiquidTracer(surface, o); }, "maxBounces");
}
