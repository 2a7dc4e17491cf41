#include "msim/solids/collision/impact_zone.hpp"

#include <algorithm>
#include <cfloat>

#include <Eigen/Geometry>
#include <Eigen/SVD>

namespace msim::solids {

namespace {

// Singular values of I below this fraction of the largest are rounding noise (a colinear zone's
// zero moment comes out near 1e-16 of the others) and are dropped by the pseudo-inverse.
constexpr double kSingularThreshold = 1e-12;

}  // namespace

RigidZoneMotion rigidZoneMotion(std::span<const int> zone, const std::vector<double>& mass,
                                const std::vector<char>& pinned, const std::vector<Vec3>& x0,
                                const std::vector<Vec3>& x1, double dt) {
  const bool heldByPins = std::any_of(zone.begin(), zone.end(), [&](int i) { return pinned[i] != 0; });
  const auto weight = [&](int i) {
    if (heldByPins) return pinned[i] != 0 ? 1.0 : 0.0;
    return mass[i];
  };

  double total = 0.0, largestCoordinate = 0.0;
  Vec3 weightedPosition = Vec3::Zero(), momentum = Vec3::Zero();
  for (const int i : zone) {
    total += weight(i);
    largestCoordinate = std::max(largestCoordinate, x0[i].cwiseAbs().maxCoeff());
    weightedPosition += weight(i) * x0[i];
    momentum += weight(i) * (x1[i] - x0[i]) / dt;
  }
  RigidZoneMotion motion;
  if (!(total > 0.0)) return motion;
  motion.centreOfMass = weightedPosition / total;
  motion.velocity = momentum / total;

  Vec3 angularMomentum = Vec3::Zero();
  Eigen::Matrix3d inertia = Eigen::Matrix3d::Zero();
  for (const int i : zone) {
    const Vec3 r = x0[i] - motion.centreOfMass;
    angularMomentum += weight(i) * r.cross((x1[i] - x0[i]) / dt);
    inertia += weight(i) * (r.squaredNorm() * Eigen::Matrix3d::Identity() - r * r.transpose());
  }
  // omega = I^+ L = V S^+ U^T L (the singular values are sorted, largest first). The offsets r
  // carry the rounding of x_cm, a few ulps of the largest coordinate per particle, and moments below
  // what that noise weighs are noise too (co-located particles would otherwise spin at 1e19 rad/s).
  const Eigen::JacobiSVD<Eigen::Matrix3d> svd(inertia, Eigen::ComputeFullU | Eigen::ComputeFullV);
  const Vec3 moments = svd.singularValues();
  const double offsetNoise = 4.0 * DBL_EPSILON * static_cast<double>(zone.size()) * largestCoordinate;
  const double smallest = std::max(kSingularThreshold * moments[0], total * offsetNoise * offsetNoise);
  Vec3 spin = svd.matrixU().transpose() * angularMomentum;
  for (int k = 0; k < 3; ++k) spin[k] = moments[k] > smallest ? spin[k] / moments[k] : 0.0;
  motion.angularVelocity = svd.matrixV() * spin;
  return motion;
}

void applyRigidImpactZone(std::span<const int> zone, const std::vector<double>& mass, const std::vector<char>& pinned,
                          const std::vector<Vec3>& x0, std::vector<Vec3>& x1, double dt) {
  const RigidZoneMotion motion = rigidZoneMotion(zone, mass, pinned, x0, x1, dt);
  const double angle = motion.angularVelocity.norm() * dt;
  const Eigen::Matrix3d rotation =
      angle > 0.0 ? Eigen::AngleAxisd(angle, motion.angularVelocity.normalized()).toRotationMatrix()
                  : Eigen::Matrix3d::Identity();
  const Vec3 centreAtEnd = motion.centreOfMass + dt * motion.velocity;
  for (const int i : zone)
    if (pinned[i] == 0) x1[i] = centreAtEnd + rotation * (x0[i] - motion.centreOfMass);
}

ImpactZones::ImpactZones(int particleCount)
    : sets_(static_cast<std::size_t>(particleCount)), collided_(static_cast<std::size_t>(particleCount), 0) {}

void ImpactZones::addCollision(std::span<const int> particles) {
  if (particles.empty()) return;
  for (const int p : particles) collided_[p] = 1;
  for (const int p : particles.subspan(1)) sets_.join(particles[0], p);
}

std::vector<std::vector<int>> ImpactZones::zones() const {
  std::vector<std::vector<int>> result;
  std::vector<int> zoneOfRoot(sets_.size(), -1);
  // Visiting the particles in increasing order sorts each zone and orders the zones.
  for (int p = 0; p < static_cast<int>(sets_.size()); ++p) {
    if (!collided_[p]) continue;
    int& zone = zoneOfRoot[static_cast<std::size_t>(sets_.root(p))];
    if (zone < 0) {
      zone = static_cast<int>(result.size());
      result.emplace_back();
    }
    result[zone].push_back(p);
  }
  return result;
}

}  // namespace msim::solids
