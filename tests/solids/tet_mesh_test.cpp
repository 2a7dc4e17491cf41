// BCC tetrahedral meshes and the torus of Selle Fig. 5.3: the tetrahedra fill the shape (volume
// within the lattice's resolution), all positively oriented and congruent; a torus crushed flat
// recovers with every tetrahedron's volume positive thanks to the altitude springs (ch. 5.3.4),
// while with edge springs alone tetrahedra stay flat or inverted.
#include <gtest/gtest.h>

#include <algorithm>
#include <cmath>
#include <numbers>

#include <Eigen/Geometry>

#include "msim/geometry/analytic_shapes.hpp"
#include "msim/solids/newmark.hpp"
#include "msim/solids/tet_mesh.hpp"

using namespace msim;
using namespace msim::solids;

namespace {

// A torus about the y axis: major radius R, minor radius r.
class Torus final : public geometry::Shape3 {
 public:
  Torus(double major, double minor) : major_(major), minor_(minor) {}
  double distance(const Vec3& x) const override {
    return std::hypot(std::hypot(x.x(), x.z()) - major_, x.y()) - minor_;
  }
  geometry::Bounds3 bounds() const override {
    const double out = major_ + minor_;
    return {Vec3(-out, -minor_, -out), Vec3(out, minor_, out)};
  }

 private:
  double major_, minor_;
};

double meshVolume(const TetMesh& mesh) {
  double v = 0.0;
  for (const auto& t : mesh.tetrahedra) {
    const Vec3& x0 = mesh.vertices[t[0]];
    v += (mesh.vertices[t[1]] - x0).cross(mesh.vertices[t[2]] - x0).dot(mesh.vertices[t[3]] - x0) / 6.0;
  }
  return v;
}

// Fraction of the system's tetrahedra with positive volume, and the smallest volume over rest.
std::pair<double, double> orientation(const MassSpringSystem& system, const TetMesh& rest) {
  int positive = 0;
  double smallest = 1e300;
  for (std::size_t t = 0; t < rest.tetrahedra.size(); ++t) {
    const double v = tetrahedronVolume6(system, rest.tetrahedra[t]);
    positive += v > 0.0;
    const Vec3& x0 = rest.vertices[rest.tetrahedra[t][0]];
    const auto& r = rest.tetrahedra[t];
    const double v0 = (rest.vertices[r[1]] - x0).cross(rest.vertices[r[2]] - x0).dot(rest.vertices[r[3]] - x0);
    smallest = std::min(smallest, v / v0);
  }
  return {double(positive) / static_cast<double>(rest.tetrahedra.size()), smallest};
}

// The torus with its vertices' y scaled by ySquash, settled for 1 s (steps of 1 ms: the springs
// are explicit sideways, docs/solids.md).
MassSpringSystem settle(const TetMesh& mesh, bool altitude, double ySquash) {
  SolidMaterial material;
  material.density = 200.0;
  material.edgeStiffness = 50.0;
  material.edgeDamping = 0.2;
  material.altitudeStiffness = altitude ? 50.0 : 0.0;
  material.altitudeDamping = altitude ? 0.2 : 0.0;
  MassSpringSystem solid = solidSystem(mesh, material);
  solid.gravity = Vec3::Zero();
  for (Vec3& x : solid.x) x.y() *= ySquash;
  NewmarkSettings settings;
  settings.implicitSprings = true;
  settings.cgTolerance = 1e-6;
  NewmarkStepper stepper(settings);
  for (int s = 0; s < 1000; ++s) stepper.step(solid, 1e-3);
  return solid;
}

}  // namespace

TEST(TetMesh, BccTetrahedraFillTheShapeCongruentAndPositive) {
  const geometry::Sphere<3> ball(Vec3(0.1, 0.2, 0.3), 0.25);
  const double h = 0.025;
  const TetMesh mesh = bccTetMesh(ball, h);
  const double exact = 4.0 / 3.0 * std::numbers::pi * std::pow(0.25, 3);
  EXPECT_NEAR(meshVolume(mesh) / exact, 1.0, 0.05);
  // BCC tetrahedra: volume h^3 / 12 each, all positively oriented.
  for (const auto& t : mesh.tetrahedra) {
    const Vec3& x0 = mesh.vertices[t[0]];
    const double v = (mesh.vertices[t[1]] - x0).cross(mesh.vertices[t[2]] - x0).dot(mesh.vertices[t[3]] - x0) / 6.0;
    ASSERT_NEAR(v, h * h * h / 12.0, 1e-12);
  }
  EXPECT_THROW(bccTetMesh(ball, 0.0), std::invalid_argument);
}

TEST(TetMesh, CrushedTorusRecoversWithAltitudeSpringsOnly) {
  // Fig. 5.3: the torus crushed to a twentieth of its thickness (every tetrahedron nearly flat).
  const TetMesh torus = bccTetMesh(Torus(0.3, 0.1), 0.06);
  ASSERT_GT(torus.tetrahedra.size(), 500u);
  const auto [recovered, smallest] = orientation(settle(torus, true, 0.05), torus);
  RecordProperty("smallest_volume_ratio", std::to_string(smallest));
  EXPECT_EQ(recovered, 1.0);
  EXPECT_GT(smallest, 0.5);
  const auto [edgesOnly, edgesSmallest] = orientation(settle(torus, false, 0.05), torus);
  RecordProperty("edges_only_positive_fraction", std::to_string(edgesOnly));
  RecordProperty("edges_only_smallest_volume_ratio", std::to_string(edgesSmallest));
  EXPECT_LT(edgesSmallest, 0.1) << "edge springs alone should leave tetrahedra flat or inverted";
}
