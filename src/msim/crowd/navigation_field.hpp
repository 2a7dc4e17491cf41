#pragma once
// Grid navigation field: one geodesic distance field phi per goal, solved by fast marching on the
// eikonal equation |grad phi| = 1 (Sethian 1996) over the walkable cells of an axis-aligned box.
// Narain 2011 (ch. 4.3.1) takes the initial segment of the globally planned path as the preferred
// direction and says any global planner will do; -grad phi is exactly that initial segment, for
// every position at once, at O(cells) memory per goal instead of the roadmap's O(V^2).
#include <cstddef>
#include <cstdint>
#include <vector>

#include "msim/core/vec.hpp"
#include "msim/crowd/goal.hpp"
#include "msim/crowd/planner.hpp"
#include "msim/crowd/polygon.hpp"

namespace msim::crowd {

struct NavigationFieldOptions {
  Vec2 lo = Vec2::Zero();             // walkable domain [m]
  Vec2 hi = Vec2::Zero();
  double cellSize = 0.25;             // [m]
  // Agent radius [m]: cells whose centre is closer than this to an obstacle are blocked, so paths
  // keep the agent's body off the walls. Raised to cellSize / 2 internally, which is what stops a
  // wall thinner than a cell from leaking between two 4-neighbour cells.
  double clearance = 0.25;
};

class NavigationField final : public GlobalPlanner {
 public:
  // Builds one field per goal (in parallel). Throws InputError naming the goal or obstacle for an
  // invalid obstacle polygon, a goal outside the domain, inside an obstacle, or without a
  // walkable cell.
  NavigationField(std::vector<Goal> goals, std::vector<Polygon> obstacles, const NavigationFieldOptions& options);

  std::size_t goalCount() const override { return goals_.size(); }
  Vec2 direction(std::size_t goal, const Vec2& position) const override;
  double distance(std::size_t goal, const Vec2& position) const override;
  // False where the goal cannot be reached from `position` (enclosed, or the position is in no
  // walkable cell's reach): the scene refuses such agents with an InputError.
  bool reachable(std::size_t goal, const Vec2& position) const;

  const NavigationFieldOptions& options() const { return options_; }
  IVec2 cells() const { return n_; }
  bool blocked(int i, int j) const { return blocked_[index(i, j)] != 0; }

 private:
  std::size_t index(int i, int j) const { return static_cast<std::size_t>(j) * n_[0] + i; }
  Vec2 centre(int i, int j) const;
  float phi(std::size_t goal, int i, int j) const { return phi_[goal][index(i, j)]; }
  // Descent direction of cell (i, j) by one-sided (upwind) differences towards the lower
  // neighbour on each axis; zero where no finite neighbour is lower.
  Vec2 cellDirection(std::size_t goal, int i, int j) const;
  // Nearest cell with finite phi within a few cells of `position`, for positions whose bilinear
  // stencil is all blocked (an agent pushed into the clearance band); false if none.
  bool nearestFinite(std::size_t goal, const Vec2& position, int& ci, int& cj) const;

  std::vector<Goal> goals_;
  NavigationFieldOptions options_;
  IVec2 n_ = IVec2::Zero();
  std::vector<std::uint8_t> blocked_;     // shared by all goals
  std::vector<std::vector<float>> phi_;   // per goal, +inf where blocked or unreachable
};

}  // namespace msim::crowd
