#pragma once
// How a mass-spring system split among processes (Selle ch. 8.2; parallel/split_cloth.hpp) shares
// its work. Every process stores every particle, as in the chapter; each particle belongs to one
// process, which computes its rows of the implicit solves. Collision impulses that touch particles
// of several processes go through the chapter's two phases, so that every process ends with the
// same velocities, those of one serial Gauss-Seidel pass in the phases' order. The solvers
// (newmark.hpp, self_repulsion.hpp) take a split and call it collectively: every process makes the
// same calls in the same order.
#include <array>
#include <cstddef>
#include <functional>
#include <span>
#include <vector>

#include "msim/core/vec.hpp"

namespace msim::solids {

class ParticleSplit {
 public:
  virtual ~ParticleSplit() = default;
  // This process's particles, ascending.
  virtual std::span<const int> owned() const = 0;
  // Overwrites the other processes' particles' entries of `values` (3 doubles per particle) with
  // their owners' values, on every process.
  virtual void shareOwned(double* values) const = 0;
  // The sum over the processes of each one's `local`, the same bits on every process.
  virtual double sum(double local) const = 0;
  // One Gauss-Seidel pass over `items` (four particles each, -1 for an unused slot) in the two
  // phases' order; respond(i) applies item i's impulse to `v`, which every process holds alike
  // before and after.
  virtual void gaussSeidel(const std::vector<std::array<int, 4>>& items, std::vector<Vec3>& v,
                           const std::function<void(std::size_t)>& respond) const = 0;
};

}  // namespace msim::solids
