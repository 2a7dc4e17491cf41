#pragma once
// How a mass-spring system split among processes (Selle ch. 8.2; parallel/split_cloth.hpp) shares
// its work. Every process stores every particle, as in the chapter; each particle belongs to one
// process, which computes its rows of the implicit solves and looks for the collision pairs of its
// points and of the edges whose first vertex it owns (what each finds is joined). Collision
// impulses that touch particles of several processes go through the chapter's two phases, so that
// every process ends with the same velocities, those of one serial Gauss-Seidel pass in the phases'
// order. The solvers (newmark.hpp, collision_pairs.hpp, self_repulsion.hpp, self_collision.hpp)
// take a split and call it collectively: every process makes the same calls in the same order.
#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <utility>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::solids {

class ParticleSplit {
 public:
  virtual ~ParticleSplit() = default;
  // This process's particles, ascending.
  virtual std::span<const int> owned() const = 0;
  // Whether particle p is this process's (asked per collision pair: no virtual call).
  bool owns(int particle) const { return mine_[static_cast<std::size_t>(particle)] != 0; }
  // Overwrites the other processes' particles' entries of `values` (3 doubles per particle) with
  // their owners' values, on every process.
  virtual void shareOwned(double* values) const = 0;
  // The sum over the processes of each one's `local`, the same bits on every process.
  virtual double sum(double local) const = 0;
  // Every process's `rows` (`width` doubles each), joined in rank order, into `rows` on every process.
  virtual void gatherRows(std::vector<double>& rows, int width) const = 0;
  // One Gauss-Seidel pass over `items` (four particles each, -1 for an unused slot) in the two
  // phases' order; respond(i) applies item i's impulse to `v`, which every process holds alike
  // before and after.
  virtual void gaussSeidel(const std::vector<std::array<int, 4>>& items, std::vector<Vec3>& v,
                           const std::function<void(std::size_t)>& respond) const = 0;

 protected:
  // mine[p] != 0 for this process's particles.
  explicit ParticleSplit(std::vector<char> mine) : mine_(std::move(mine)) {}

 private:
  std::vector<char> mine_;
};

}  // namespace msim::solids
