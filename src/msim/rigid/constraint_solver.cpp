#include "msim/rigid/constraint_solver.hpp"

#include <algorithm>
#include <cmath>

#include <Eigen/Cholesky>

namespace msim::rigid {
namespace {

// Velocity state copied out of the bodies for the solve; index bodies.size() is the world.
struct Dyn {
  double invMass = 0.0;
  Eigen::Matrix3d invInertia = Eigen::Matrix3d::Zero();
  Vec3 position = Vec3::Zero();
  Vec3 v = Vec3::Zero();
  Vec3 w = Vec3::Zero();
};

struct ContactRow {
  int a, b;
  Vec3 ra, rb, n, t1, t2;
  double massN, massT1, massT2, bias, mu;
  double lambdaN = 0.0;
  Eigen::Vector2d lambdaT = Eigen::Vector2d::Zero();
};

void tangentBasis(const Vec3& n, Vec3& t1, Vec3& t2) {
  // Deterministic basis: cross with the axis least aligned with n.
  const Vec3 helper = std::abs(n.x()) < 0.57 ? Vec3(Vec3::UnitX()) : Vec3(Vec3::UnitY());
  t1 = n.cross(helper).normalized();
  t2 = n.cross(t1);
}

double effectiveMass(const Dyn& A, const Dyn& B, const Vec3& ra, const Vec3& rb, const Vec3& d) {
  const Vec3 ca = ra.cross(d), cb = rb.cross(d);
  const double k = A.invMass + B.invMass + ca.dot(A.invInertia * ca) + cb.dot(B.invInertia * cb);
  return k > 0.0 ? 1.0 / k : 0.0;
}

Vec3 relativeVelocity(const Dyn& A, const Dyn& B, const Vec3& ra, const Vec3& rb) {
  return A.v + A.w.cross(ra) - B.v - B.w.cross(rb);
}

void applyPair(Dyn& A, Dyn& B, const Vec3& ra, const Vec3& rb, const Vec3& p) {
  A.v += A.invMass * p;
  A.w += A.invInertia * ra.cross(p);
  B.v -= B.invMass * p;
  B.w -= B.invInertia * rb.cross(p);
}

void solveContact(ContactRow& c, std::vector<Dyn>& dyn) {
  Dyn& A = dyn[c.a];
  Dyn& B = dyn[c.b];
  // Friction first, bounded by the normal impulse of the previous sweep (Box2D order).
  const Vec3 vr = relativeVelocity(A, B, c.ra, c.rb);
  const Eigen::Vector2d dT(-vr.dot(c.t1) * c.massT1, -vr.dot(c.t2) * c.massT2);
  Eigen::Vector2d total = c.lambdaT + dT;
  const double limit = c.mu * c.lambdaN;
  if (total.norm() > limit) total *= limit / total.norm();
  const Eigen::Vector2d applied = total - c.lambdaT;
  c.lambdaT = total;
  applyPair(A, B, c.ra, c.rb, applied.x() * c.t1 + applied.y() * c.t2);

  const double vn = relativeVelocity(A, B, c.ra, c.rb).dot(c.n);
  const double newLambda = std::max(c.lambdaN - (vn - c.bias) * c.massN, 0.0);
  const double dN = newLambda - c.lambdaN;
  c.lambdaN = newLambda;
  applyPair(A, B, c.ra, c.rb, dN * c.n);
}

void solveHinge(const Hinge& h, const Eigen::Matrix3d& R, Dyn& d, double beta, double dt) {
  const Vec3 r = R * h.localAnchor;
  const Vec3 aBody = R * h.localAxis;
  Vec3 t1, t2;
  tangentBasis(h.axis, t1, t2);
  Eigen::Matrix<double, 5, 6> J = Eigen::Matrix<double, 5, 6>::Zero();
  Eigen::Matrix3d rx;
  rx << 0, -r.z(), r.y(), r.z(), 0, -r.x(), -r.y(), r.x(), 0;
  J.block<3, 3>(0, 0).setIdentity();
  J.block<3, 3>(0, 3) = -rx;  // omega x r = -[r]x omega
  J.block<1, 3>(3, 3) = t1.transpose();
  J.block<1, 3>(4, 3) = t2.transpose();
  Eigen::Matrix<double, 6, 6> Minv = Eigen::Matrix<double, 6, 6>::Zero();
  Minv.topLeftCorner<3, 3>() = Eigen::Matrix3d::Identity() * d.invMass;
  Minv.bottomRightCorner<3, 3>() = d.invInertia;
  Eigen::Matrix<double, 5, 1> target;
  const Vec3 drift = d.position + r - h.pivot;
  const Vec3 axisError = aBody.cross(h.axis);
  target.head<3>() = -beta / dt * drift;
  target(3) = beta / dt * t1.dot(axisError);
  target(4) = beta / dt * t2.dot(axisError);
  Eigen::Matrix<double, 6, 1> V;
  V << d.v, d.w;
  const Eigen::Matrix<double, 5, 5> K = J * Minv * J.transpose();
  const Eigen::Matrix<double, 5, 1> lambda = K.ldlt().solve(target - J * V);
  V += Minv * J.transpose() * lambda;
  d.v = V.head<3>();
  d.w = V.tail<3>();
}

}  // namespace

void solveConstraints(std::vector<RigidBody>& bodies, const std::vector<Contact>& contacts,
                      const std::vector<Hinge>& hinges, const SolverSettings& s, double dt) {
  if (contacts.empty() && hinges.empty()) return;
  const int n = static_cast<int>(bodies.size());
  std::vector<Dyn> dyn(n + 1);
  std::vector<Eigen::Matrix3d> rotations(n);
  for (int i = 0; i < n; ++i) {
    const RigidBody& b = bodies[i];
    rotations[i] = b.rotation();
    dyn[i] = {b.inverseMass(), rotations[i] * b.bodyInverseInertia() * rotations[i].transpose(),
              b.position, b.velocity, b.angularVelocity};
  }
  std::vector<ContactRow> rows;
  rows.reserve(contacts.size());
  for (const Contact& c : contacts) {
    ContactRow row;
    row.a = c.a;
    row.b = c.b == kWorld ? n : c.b;
    const Dyn& A = dyn[row.a];
    const Dyn& B = dyn[row.b];
    row.ra = c.point - A.position;
    row.rb = row.b == n ? Vec3(Vec3::Zero()) : Vec3(c.point - B.position);
    row.n = c.normal;
    tangentBasis(c.normal, row.t1, row.t2);
    row.massN = effectiveMass(A, B, row.ra, row.rb, row.n);
    row.massT1 = effectiveMass(A, B, row.ra, row.rb, row.t1);
    row.massT2 = effectiveMass(A, B, row.ra, row.rb, row.t2);
    row.mu = c.friction;
    const double vn0 = relativeVelocity(A, B, row.ra, row.rb).dot(row.n);
    const bool bounce = c.restitution > 0.0 && -vn0 > s.restitutionThreshold;
    if (c.depth < 0.0) {
      // Speculative: may close the gap this step, no more; bounce if it would cross it.
      row.bias = (bounce && -vn0 * dt > -c.depth) ? -c.restitution * vn0 : c.depth / dt;
    } else {
      row.bias = s.baumgarte / dt * std::max(c.depth - s.slop, 0.0);
      if (bounce) row.bias = std::max(row.bias, -c.restitution * vn0);
    }
    rows.push_back(row);
  }
  for (int it = 0; it < s.iterations; ++it) {
    for (const Hinge& h : hinges) solveHinge(h, rotations[h.body], dyn[h.body], s.baumgarte, dt);
    for (ContactRow& row : rows) solveContact(row, dyn);
  }
  for (int i = 0; i < n; ++i) {
    if (bodies[i].isStatic()) continue;
    bodies[i].velocity = dyn[i].v;
    bodies[i].angularVelocity = dyn[i].w;
  }
}

}  // namespace msim::rigid
