// Contact and friction with bodies (Selle ch. 6.5) on the seed's incline (Figs. 6.6-6.7,
// theta = pi / 5, g = 9.8): a particle and a tetrahedron starting at rest with mu = 0.6 slide
// down at g (sin theta - mu cos theta) = 1.0033 m/s^2 (x(1 s) = 0.5016 m); starting at 1 m/s
// down the slope with mu = 0.9 they decelerate at 1.3754 m/s^2 and stop at t = 0.7271 s after
// 0.3636 m. Within 1% (the issue). The earlier projection method (the seed's [16]) slides too far
// at the same step (friction acts one step late).
#include <gtest/gtest.h>

#include <cmath>
#include <memory>
#include <numbers>

#include "msim/geometry/analytic_shapes.hpp"
#include "msim/geometry/shape_adapters.hpp"
#include "msim/solids/body_contact.hpp"
#include "msim/solids/mass_spring.hpp"
#include "msim/solids/newmark.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

const double kTheta = std::numbers::pi / 5.0, kG = 9.8;
const Vec3 kNormal(-std::sin(kTheta), std::cos(kTheta), 0.0);    // the incline's outward normal
const Vec3 kDownhill(-std::cos(kTheta), -std::sin(kTheta), 0.0);  // along the surface

BodyContact incline(double mu, ContactMethod method = ContactMethod::CrossingFraction) {
  BodyContact contact(method);
  contact.addBody({std::make_shared<geometry::Plane<3>>(Vec3::Zero(), kNormal), Vec3::Zero(), mu});
  return contact;
}

struct Slide {
  double distance = 0.0;   // down the slope after `duration` (or when it stopped) [m]
  double stopTime = -1.0;  // when the speed first fell below 1e-9 [s]
};

// Centroid motion of `system` (resting on the incline) over `duration`, steps of dt.
Slide slide(MassSpringSystem system, const BodyContact& contact, double dt, double duration, bool implicitSprings) {
  NewmarkSettings settings;
  settings.implicitSprings = implicitSprings;
  settings.cgTolerance = 1e-12;
  NewmarkStepper stepper(settings);
  auto centroid = [&]() {
    Vec3 c = Vec3::Zero();
    for (const Vec3& x : system.x) c += x;
    return Vec3(c / static_cast<double>(system.size()));
  };
  const Vec3 start = centroid();
  Slide result;
  const int steps = static_cast<int>(std::lround(duration / dt));
  for (int s = 1; s <= steps; ++s) {
    stepper.step(system, dt, &contact);
    Vec3 v = Vec3::Zero();
    for (const Vec3& u : system.v) v += u;
    if (result.stopTime < 0.0 && (v / static_cast<double>(system.size())).norm() < 1e-9) result.stopTime = s * dt;
  }
  result.distance = (centroid() - start).dot(kDownhill);
  return result;
}

MassSpringSystem particle(double speed) {
  MassSpringSystem system;
  system.gravity = Vec3(0.0, -kG, 0.0);
  system.addParticle(Vec3::Zero(), 0.01, speed * kDownhill);
  return system;
}

// A regular tetrahedron of edge 0.1 m with one face on the incline, stiff edge springs.
MassSpringSystem tetrahedron(double speed) {
  const double e = 0.1;
  const Vec3 u = kDownhill, w(0.0, 0.0, 1.0);
  const Vec3 a = Vec3::Zero(), b = e * u, c = 0.5 * e * u + (std::sqrt(3.0) / 2.0) * e * w;
  const Vec3 top = (a + b + c) / 3.0 + std::sqrt(2.0 / 3.0) * e * kNormal;
  MassSpringSystem system;
  system.gravity = Vec3(0.0, -kG, 0.0);
  for (const Vec3& x : {a, b, c, top}) system.addParticle(x, 0.01, speed * kDownhill);
  for (int i = 0; i < 4; ++i)
    for (int j = i + 1; j < 4; ++j) system.addSpring(i, j, 2000.0, 0.5);
  return system;
}

}  // namespace

TEST(BodyContact, ParticleAcceleratesDownTheInclineAsCoulombFrictionAllows) {
  const Slide s = slide(particle(0.0), incline(0.6), 1e-3, 1.0, false);
  RecordProperty("distance", std::to_string(s.distance));
  EXPECT_NEAR(s.distance / 0.5016, 1.0, 0.01);
  // The crossing fraction puts the friction inside the step: the same at 30 steps per second.
  EXPECT_NEAR(slide(particle(0.0), incline(0.6), 1.0 / 30.0, 1.0, false).distance / 0.5016, 1.0, 0.01);
}

TEST(BodyContact, ParticleStopsWhereAndWhenCoulombFrictionSays) {
  const Slide s = slide(particle(1.0), incline(0.9), 1e-3, 1.0, false);
  RecordProperty("stop_time", std::to_string(s.stopTime));
  RecordProperty("distance", std::to_string(s.distance));
  EXPECT_NEAR(s.stopTime / 0.7271, 1.0, 0.01);
  EXPECT_NEAR(s.distance / 0.3636, 1.0, 0.01);
}

TEST(BodyContact, TetrahedronSlidesAndStopsAsTheParticleDoes) {
  const Slide accelerating = slide(tetrahedron(0.0), incline(0.6), 2e-4, 1.0, true);
  RecordProperty("accelerating_distance", std::to_string(accelerating.distance));
  EXPECT_NEAR(accelerating.distance / 0.5016, 1.0, 0.01);
  const Slide stopping = slide(tetrahedron(1.0), incline(0.9), 2e-4, 1.0, true);
  RecordProperty("stopping_distance", std::to_string(stopping.distance));
  EXPECT_NEAR(stopping.distance / 0.3636, 1.0, 0.01);
}

TEST(BodyContact, ProjectionMethodSlidesTooFar) {
  // At 30 steps per second the projection's friction comes a step late: about 16% too far.
  const Slide projected = slide(particle(0.0), incline(0.6, ContactMethod::Projection), 1.0 / 30.0, 1.0, false);
  RecordProperty("projection_distance_over_exact", std::to_string(projected.distance / 0.5016));
  EXPECT_GT(projected.distance / 0.5016, 1.05);
}

// A turntable (a box turning about the vertical at 2 rad/s, geometry::RigidlyMoved) carries a
// particle resting on it 0.3 m from the axis once friction has spun it up (mu g = 9.8 m/s^2 takes
// 0.06 s to reach omega r = 0.6 m/s, and holds the centripetal omega^2 r = 1.2 m/s^2): after 1 s it
// turns with the table at the same radius. Without friction the table turns under it and it stays.
TEST(BodyContact, TurningBodyCarriesAParticleByFriction) {
  const geometry::RigidMotion turn{Vec3::Zero(), Vec3(0.0, 2.0, 0.0), Vec3::Zero()};
  const auto table = std::make_shared<geometry::Box<3>>(Vec3(-0.5, -0.1, -0.5), Vec3(0.5, 0.0, 0.5));
  auto run = [&](double mu) {
    MassSpringSystem system;
    system.addParticle(Vec3(0.3, 1e-6, 0.0), 0.01);
    ContactBody body{table, Vec3::Zero(), mu, turn.angularVelocity, Vec3::Zero()};
    BodyContact contact;
    contact.addBody(body);
    NewmarkStepper stepper;
    const double dt = 1e-3;
    for (int s = 1; s <= 1000; ++s) {
      body.shape = std::make_shared<geometry::RigidlyMoved>(table, turn, s * dt);  // where the step ends
      contact.setBody(0, body);
      stepper.step(system, dt, &contact);
      EXPECT_GT(system.x[0].y(), -1e-9) << "step " << s;
    }
    return system;
  };
  const MassSpringSystem carried = run(1.0);
  const Vec3 x = carried.x[0], v = carried.v[0];
  EXPECT_NEAR(std::hypot(x.x(), x.z()), 0.3, 0.003);
  EXPECT_NEAR(std::hypot(v.x(), v.z()), 0.6, 0.006);
  // Turning the same way as the table: the angular momentum's y component is positive (omega_y > 0
  // turns +x towards -z).
  EXPECT_GT(x.z() * v.x() - x.x() * v.z(), 0.0);
  const MassSpringSystem slipping = run(0.0);
  EXPECT_LT((slipping.x[0] - Vec3(0.3, 0.0, 0.0)).norm(), 1e-3);
  EXPECT_LT(slipping.v[0].norm(), 1e-6);
}
