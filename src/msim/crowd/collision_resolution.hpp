#pragma once
// Pairwise collision resolution (Narain 2011, ch. 4.3.3, after Treuille et al. 2006): after the
// agents have moved, pairs closer than a separation distance are pushed apart along their centre
// line, agents are pushed out of static obstacles and kept inside the domain. The UIC has already
// prevented gross overcrowding, so a few cheap sweeps are enough (the seed measured < 0.12% of
// agents slightly closer than d_min over the circle scene, ch. 4.5.1).
#include <cstdint>
#include <span>
#include <vector>

#include "msim/crowd/agents.hpp"
#include "msim/crowd/neighbour_grid.hpp"
#include "msim/crowd/obstacle_index.hpp"

namespace msim::crowd {

// Axis-aligned box the agents must stay in (centres at least their radius from the walls).
struct DomainBox {
  Vec2f lo, hi;
};

struct CollisionResolutionParams {
  // Pairs closer than separation * d_min (d_min = r_i + r_j) are pushed to that distance. The
  // seed found a target "somewhat larger than d_min" gave smoother, jitter-free motion and a better
  // spacing (ch. 4.5.1). With the UIC's alpha = 0.56 packing and 6 Gauss-Seidel sweeps (the scene
  // defaults), 1.2 gives the circle scene of Fig. 4.5 about 0.004% of agent-frames closer than
  // d_min (chaotic: it moves with the sweep order) and a mean nearest-neighbour distance of 1.18
  // d_min in dense regions (the seed: 0.12% and 1.25). The target must leave room: at alpha 0.64
  // the separation discs at rho_max are at random close packing, the sweeps never converge and
  // cost three times as much.
  float separation = 1.2f;
  // Most sweeps; each resolves isolated pairs exactly, clusters converge geometrically. 6
  // Gauss-Seidel sweeps give the circle scene the quality 12 Jacobi sweeps gave (the scene
  // default, crowd.collision_resolution.iterations, is the same).
  int iterations = 6;
  // GaussSeidel (default): each pair is projected once per sweep, in place, both agents moved
  // by half (equal and opposite); rows of cells are done in two phases (even rows, then odd),
  // so the result does not depend on the thread count. Converges about twice as fast per sweep
  // as Jacobi. Jacobi: all pushes from the positions before the sweep (Treuille et al. 2006).
  enum class Sweeps { GaussSeidel, Jacobi };
  Sweeps sweeps = Sweeps::GaussSeidel;
  // Convergence, as a fraction of d_min (the largest one's). Gauss-Seidel converges locally: after
  // a sweep only the neighbourhoods of agents that moved more than this since their pairs were
  // last projected are projected again (the whole crowd while many did, else just those agents'
  // pairs), and the sweeps stop once there are none. After a step a few pairs overlap: in the
  // 100k circle 1-3% of the agents are active after the first sweep, so the later sweeps cost
  // little. Jacobi stops once a sweep moved nobody by more. 0 = always run `iterations` sweeps
  // over the whole crowd. 0.03 d_min is 1.5 cm for adult agents.
  float tolerance = 0.03f;
};

class CollisionResolver {
 public:
  // Moves agents.position in place. Gauss-Seidel (default): each pair closer than the target is
  // projected in place, both agents moved by half the correction (a scripted agent's partner by
  // all of it). A whole sweep takes each pair once, owned by its first agent in cell order: an
  // agent's partners are the later agents of its cell, of the cell to its right and of the three
  // cells above, tested eight at a time. Those lie in two rows of cells, so the even rows of
  // cells run in parallel, then the odd rows: the order is fixed, and the result does not depend
  // on the thread count. Pushes are equal and opposite, so the centroid is conserved to round-off
  // unless an obstacle, the domain or a scripted agent intervenes. After each sweep agents are
  // pushed out of obstacles and clamped into the domain. After the first sweep only the agents
  // that moved more than the tolerance since their own pairs were last projected ("active") have
  // their pairs projected again: while over a 16th of the crowd is active, by a whole sweep;
  // else each active agent with every agent near it, rows of cells three apart in parallel and
  // each row's agents in slot order (still independent of the thread count).
  // Jacobi: every displacement from the positions before the sweep, then applied, over the 3x3
  // cells around each agent. No allocation once warm.
  //
  // The agents are bucketed into cells and their positions, radii and models gathered in cell
  // order; the sweeps run on that copy and the result is scattered back at the end. The buckets
  // are redone when an agent may have moved far enough from where they were made for a pair
  // within range to lie beyond neighbouring cells, so the pair sets are exact (Gauss-Seidel: the
  // farthest any agent has been is tracked through the sweep, and a whole sweep that went too far
  // is undone and redone on new buckets; only the first sweep on new buckets is kept regardless,
  // which matters only from deep overlaps such as uniformly random positions; the local sweeps
  // search as far around an agent as the farthest agent has gone, so they need no new buckets).
  void resolve(Agents& agents, const StaticObstacles& obstacles, const DomainBox& domain,
               const CollisionResolutionParams& params = {});

  // Times the agents were bucketed in the last resolve() (1 unless agents moved far), for tests
  // and benchmarks.
  int lastBucketings() const { return bucketings_; }
  // Sweeps the last resolve() ran (<= iterations; fewer when it converged), whole or local.
  int lastSweeps() const { return sweeps_; }
  // Gauss-Seidel sweeps of the last resolve() that projected only around active agents.
  int lastLocalSweeps() const { return localSweeps_; }
  // Gauss-Seidel sweeps of the last resolve() that were undone and redone on new buckets (an
  // agent moved too far during the sweep for the cells to be sure to hold all its pairs).
  int lastRedoneSweeps() const { return redone_; }

 private:
  // The sweeps on the bucketed copy; range: the largest target distance, tolerance2: the squared
  // largest displacement of a converged sweep.
  void resolveGaussSeidel(const StaticObstacles& obstacles, const DomainBox& domain,
                          const CollisionResolutionParams& params, float range, float tolerance2);
  void resolveJacobi(const StaticObstacles& obstacles, const DomainBox& domain, const CollisionResolutionParams& params,
                     float range, float tolerance2);
  void bucket(const Agents& agents, float cellSize);  // from the agents
  void rebucket(float cellSize);                       // from the current cell-ordered copy
  void resizeCellFlags();  // Jacobi: one moved flag per cell of the current buckets
  void scatter(Agents& agents) const;                  // positions back to agent order
  // Gauss-Seidel: the sweeps start from the bucketed positions.
  void startSweeps();
  struct SweepMoves {
    float far2 = 0.0f;        // squared largest distance from the bucketed positions at any moment
    float end2 = 0.0f;        // the same at the end of the sweep
    std::size_t active = 0;   // agents active after the sweep
  };
  // One whole Gauss-Seidel sweep in place over x_, y_ (start positions in prevX_, prevY_, end
  // positions into nextX_, nextY_).
  SweepMoves gaussSeidelSweep(const StaticObstacles& obstacles, const DomainBox& domain, float s, float tolerance2);
  // The end of a whole sweep for the slots [k0, k1): clamps them into the domain, records where
  // they end, marks the active ones and folds their distances into w.
  void clampIntoDomain(std::size_t k0, std::size_t k1, const DomainBox& domain, float tolerance2, SweepMoves& w);
  // One local sweep over the active agents (activeSlots_), which it replaces by those of the next
  // sweep. lastEnd2: end2 of the sweep before (the agents it does not move stay there).
  SweepMoves localSweep(const StaticObstacles& obstacles, const DomainBox& domain, float s, float range,
                        float tolerance2, float lastEnd2);
  void gatherActive();  // activeSlots_ from active_

  NeighbourGrid grid_;
  // Cell-ordered copies (slot k is agent agent_[k]).
  // Structure of arrays, padded with kPad far-away slots so the vector loops may read past a range.
  std::vector<float> x_, y_, nextX_, nextY_;  // positions before / after a sweep
  // Gauss-Seidel: positions at the start of the sweep (x_, y_ are updated in place; nextX_,
  // nextY_ receive the end positions), and per slot the squared largest distance from its
  // bucketed position in the sweep so far.
  std::vector<float> prevX_, prevY_, far_;
  // Gauss-Seidel, per slot: where the agent was when its pairs were last all projected, and
  // whether it moved more than the tolerance from there (active), and whether the local sweep
  // under way moved it. The active slots in slot order.
  std::vector<float> checkX_, checkY_;
  std::vector<std::uint8_t> active_, touchedMark_;
  std::vector<std::uint32_t> activeSlots_;
  // Local sweeps: the active agents of one row of cells (activeSlots_[begin, end)), the agents
  // the group moved and those of them still active after the sweep, its scratch (the slot ranges
  // near an agent), the agents it left to the serial pass, and its F^2.
  struct RowGroup {
    int row = 0;
    std::size_t begin = 0, end = 0;
    std::vector<std::uint32_t> touched, active, lo, hi, deferred;
    float farthest2 = 0.0f;
  };
  std::vector<RowGroup> rowGroups_;
  std::vector<float> bucketX_, bucketY_;  // positions when bucketed
  std::vector<float> radius_;
  std::vector<float> yield_;  // share of a push a neighbour of this agent takes: 1/2, or 1 if this one is scripted
  std::vector<std::uint8_t> scripted_;
  std::vector<std::uint32_t> agent_;  // agent index of each slot
  // Rebucketing scratch: positions to bucket, and the permuted copies before they are swapped in.
  std::vector<Vec2f> points_;
  std::vector<float> tmpRadius_, tmpYield_;
  std::vector<std::uint8_t> tmpScripted_;
  std::vector<std::uint32_t> tmpAgent_;
  // Jacobi, per cell: whether any of its agents moved in the last sweep (and in the one being
  // computed). A cell whose whole stencil did not move is skipped: its agents would not move either.
  std::vector<std::uint8_t> moved_, movedNext_;
  int bucketings_ = 0;
  int sweeps_ = 0;
  int localSweeps_ = 0;
  int redone_ = 0;
};

}  // namespace msim::crowd
