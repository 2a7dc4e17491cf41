// Mass properties against closed forms: sphere and box formulas, and the divergence-theorem
// integrals (Eberly 2002) on a box mesh and a tetrahedron.
#include "msim/rigid/mass_properties.hpp"

#include <gtest/gtest.h>

#include <numbers>
#include <string>
#include <utility>

#include "msim/core/error.hpp"
#include "test_meshes.hpp"

namespace msim::rigid {
namespace {

constexpr double kTol = 1e-12;

void expectMatrixNear(const Eigen::Matrix3d& a, const Eigen::Matrix3d& b, double tol) {
  EXPECT_LE((a - b).cwiseAbs().maxCoeff(), tol) << "got\n" << a << "\nexpected\n" << b;
}

TEST(RigidMassProperties, SphereMatchesClosedForm) {
  const double rho = 2.5, r = 0.3;
  const MassProperties p = sphereMassProperties(Sphere{r}, rho);
  const double m = rho * 4.0 / 3.0 * std::numbers::pi * r * r * r;
  EXPECT_NEAR(p.mass, m, kTol);
  expectMatrixNear(p.inertia, Eigen::Matrix3d::Identity() * 0.4 * m * r * r, kTol);
  EXPECT_EQ(p.centreOfMass, Vec3::Zero());
}

TEST(RigidMassProperties, BoxMatchesClosedForm) {
  const double rho = 3.0;
  const MassProperties p = boxMassProperties(Box{Vec3(0.5, 1.0, 1.5)}, rho);
  const double m = rho * 1.0 * 2.0 * 3.0;
  EXPECT_NEAR(p.mass, m, kTol);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Zero();
  expected.diagonal() << m / 12 * (4 + 9), m / 12 * (1 + 9), m / 12 * (1 + 4);
  expectMatrixNear(p.inertia, expected, kTol);
}

TEST(RigidMassProperties, BoxMeshMatchesBoxFormulaAndCentre) {
  const Vec3 lo(1.0, -2.0, 0.5), hi(2.0, 0.0, 3.5);  // sides 1, 2, 3, off the origin
  const double rho = 3.0;
  const MassProperties mesh = meshMassProperties(testing::boxMesh(lo, hi), rho);
  const MassProperties box = boxMassProperties(Box{(hi - lo) / 2}, rho);
  EXPECT_NEAR(mesh.mass, box.mass, kTol);
  EXPECT_LE((mesh.centreOfMass - (lo + hi) / 2).norm(), kTol);
  expectMatrixNear(mesh.inertia, box.inertia, kTol);
}

TEST(RigidMassProperties, TetrahedronMatchesClosedForm) {
  // Unit right tetrahedron: V = 1/6, c = (1/4,1/4,1/4); about c, I_xx = rho/80 and
  // I_xy = -rho (int xy - V c_x c_y) = -rho (1/120 - 1/96) = rho/480.
  const double rho = 2.0;
  const MassProperties p = meshMassProperties(testing::tetrahedronMesh(), rho);
  EXPECT_NEAR(p.mass, rho / 6.0, kTol);
  EXPECT_LE((p.centreOfMass - Vec3::Constant(0.25)).norm(), kTol);
  Eigen::Matrix3d expected = Eigen::Matrix3d::Constant(rho / 480.0);
  expected.diagonal().setConstant(rho / 80.0);
  expectMatrixNear(p.inertia, expected, kTol);
}

TEST(RigidMassProperties, ConvexMeshIsCentredOnItsCentreOfMass) {
  const ConvexMesh m = makeConvexMesh(testing::tetrahedronMesh());
  EXPECT_LE((m.vertices[0] - Vec3::Constant(-0.25)).norm(), kTol);
  const MassProperties p = shapeMassProperties(m, 1.0);
  EXPECT_LE(p.centreOfMass.norm(), kTol);
}

TEST(RigidMassProperties, RejectsBadInput) {
  EXPECT_THROW(sphereMassProperties(Sphere{1.0}, 0.0), InputError);
  EXPECT_THROW(sphereMassProperties(Sphere{1.0}, -1.0), InputError);
  EXPECT_THROW(sphereMassProperties(Sphere{-1.0}, 1.0), InputError);
  EXPECT_THROW(boxMassProperties(Box{Vec3(1, 0, 1)}, 1.0), InputError);

  TriangleMesh open = testing::boxMesh(Vec3::Zero(), Vec3::Ones());
  open.triangles.pop_back();
  EXPECT_THROW(meshMassProperties(open, 1.0), InputError);

  TriangleMesh inverted = testing::tetrahedronMesh();
  for (auto& t : inverted.triangles) std::swap(t[1], t[2]);
  EXPECT_THROW(meshMassProperties(inverted, 1.0), InputError);

  TriangleMesh flat = testing::tetrahedronMesh();
  flat.vertices[3] = Vec3(0.3, 0.3, 0.0);
  EXPECT_THROW(meshMassProperties(flat, 1.0), InputError);

  TriangleMesh badIndex = testing::tetrahedronMesh();
  badIndex.triangles[0][0] = 7;
  EXPECT_THROW(meshMassProperties(badIndex, 1.0), InputError);

  EXPECT_THROW(meshMassProperties(TriangleMesh{}, 1.0), InputError);
  try {
    meshMassProperties(open, 1.0);
  } catch (const InputError& e) {
    EXPECT_NE(std::string(e.what()).find("not closed"), std::string::npos) << e.what();
  }
}

}  // namespace
}  // namespace msim::rigid
