#pragma once
// A collision pair as four particles and weights whose weighted sum is the pair's relative
// position (or velocity): for a point and a triangle, x_p - sum w_i x_i with the closest point's
// barycentric weights; for two edges, the first's closest point minus the second's. An impulse I
// along n changes particle i's velocity by weight_i I n / m_i, which keeps the total momentum and
// changes the relative velocity by I sum weight_i^2 / m_i (Bridson, Fedkiw & Anderson 2002 sec.
// 7.1, for any masses; pinned particles have 1 / m = 0).
#include <array>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/solids/collision_pairs.hpp"

namespace msim::solids {

struct ContactStencil {
  std::array<int, 4> node{};
  std::array<double, 4> weight{};

  static ContactStencil pointTriangle(int point, const std::array<int, 3>& triangle, const Vec3& w) {
    return {{point, triangle[0], triangle[1], triangle[2]}, {1.0, -w[0], -w[1], -w[2]}};
  }
  static ContactStencil edgeEdge(const std::array<int, 2>& e, const std::array<int, 2>& f, double s, double t) {
    return {{e[0], e[1], f[0], f[1]}, {1.0 - s, s, -(1.0 - t), -t}};
  }

  Vec3 relative(const std::vector<Vec3>& values) const {
    Vec3 sum = Vec3::Zero();
    for (int i = 0; i < 4; ++i) sum += weight[i] * values[static_cast<std::size_t>(node[i])];
    return sum;
  }
  // sum weight_i^2 / m_i: the relative velocity's change per unit impulse; 0 when all are pinned.
  double inverseMass(const std::vector<double>& inverseMasses) const {
    double sum = 0.0;
    for (int i = 0; i < 4; ++i) sum += weight[i] * weight[i] * inverseMasses[static_cast<std::size_t>(node[i])];
    return sum;
  }
  // Changes the relative velocity by `change` (a vector), momentum kept.
  void changeRelative(const Vec3& change, const std::vector<double>& inverseMasses, std::vector<Vec3>& velocity) const {
    const double im = inverseMass(inverseMasses);
    if (!(im > 0.0)) return;
    const Vec3 impulse = change / im;
    for (int i = 0; i < 4; ++i) {
      const auto p = static_cast<std::size_t>(node[i]);
      velocity[p] += weight[i] * inverseMasses[p] * impulse;
    }
  }
};

}  // namespace msim::solids
